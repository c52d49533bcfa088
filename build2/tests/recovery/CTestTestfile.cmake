# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/recovery
# Build directory: /work/wt-survey/build2/tests/recovery
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/recovery/test_recovery[1]_include.cmake")
