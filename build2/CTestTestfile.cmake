# CMake generated Testfile for 
# Source directory: /work/wt-survey
# Build directory: /work/wt-survey/build2
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
subdirs("src")
subdirs("apps/hsr")
subdirs("tests")
subdirs("bench")
subdirs("python")
