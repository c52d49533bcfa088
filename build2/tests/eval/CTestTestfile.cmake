# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/eval
# Build directory: /work/wt-survey/build2/tests/eval
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/eval/test_eval[1]_include.cmake")
