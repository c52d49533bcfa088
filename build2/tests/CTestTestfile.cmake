# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests
# Build directory: /work/wt-survey/build2/tests
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
subdirs("core")
subdirs("io")
subdirs("synth")
subdirs("eval")
subdirs("structure")
subdirs("scene")
subdirs("visibility")
subdirs("recovery")
subdirs("hulls")
subdirs("partition")
subdirs("extraction")
subdirs("pipeline")
subdirs("report")
subdirs("cli")
subdirs("corpus")
subdirs("reliability")
subdirs("city")
subdirs("tiles3d")
