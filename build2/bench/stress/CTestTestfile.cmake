# CMake generated Testfile for 
# Source directory: /work/wt-survey/bench/stress
# Build directory: /work/wt-survey/build2/bench/stress
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
