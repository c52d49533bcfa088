# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/visibility
# Build directory: /work/wt-survey/build2/tests/visibility
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/visibility/test_visibility[1]_include.cmake")
