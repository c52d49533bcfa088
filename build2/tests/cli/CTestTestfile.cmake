# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/cli
# Build directory: /work/wt-survey/build2/tests/cli
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/cli/test_cli[1]_include.cmake")
include("/work/wt-survey/build2/tests/cli/test_batch[1]_include.cmake")
