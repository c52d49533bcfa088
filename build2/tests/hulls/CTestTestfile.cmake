# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/hulls
# Build directory: /work/wt-survey/build2/tests/hulls
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/hulls/test_hulls[1]_include.cmake")
