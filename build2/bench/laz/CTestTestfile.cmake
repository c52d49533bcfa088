# CMake generated Testfile for 
# Source directory: /work/wt-survey/bench/laz
# Build directory: /work/wt-survey/build2/bench/laz
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
