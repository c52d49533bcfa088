# CMake generated Testfile for 
# Source directory: /work/wt-survey/bench
# Build directory: /work/wt-survey/build2/bench
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
subdirs("structure")
subdirs("partition")
subdirs("recovery")
subdirs("baselines")
subdirs("stress")
subdirs("laz")
subdirs("indoor")
