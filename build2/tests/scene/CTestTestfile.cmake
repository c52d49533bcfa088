# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/scene
# Build directory: /work/wt-survey/build2/tests/scene
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/scene/test_scene[1]_include.cmake")
