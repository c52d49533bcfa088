# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/structure
# Build directory: /work/wt-survey/build2/tests/structure
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/structure/structure_test[1]_include.cmake")
include("/work/wt-survey/build2/tests/structure/structure_synth_test[1]_include.cmake")
include("/work/wt-survey/build2/tests/structure/structure_cgal_equivalence_test[1]_include.cmake")
