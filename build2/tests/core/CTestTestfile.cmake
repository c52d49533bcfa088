# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/core
# Build directory: /work/wt-survey/build2/tests/core
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/core/test_core[1]_include.cmake")
include("/work/wt-survey/build2/tests/core/test_budget[1]_include.cmake")
