# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/pipeline
# Build directory: /work/wt-survey/build2/tests/pipeline
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/pipeline/test_pipeline[1]_include.cmake")
include("/work/wt-survey/build2/tests/pipeline/test_building[1]_include.cmake")
include("/work/wt-survey/build2/tests/pipeline/test_faces[1]_include.cmake")
include("/work/wt-survey/build2/tests/pipeline/test_building_roofs[1]_include.cmake")
include("/work/wt-survey/build2/tests/pipeline/test_indoor[1]_include.cmake")
