# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/city
# Build directory: /work/wt-survey/build2/tests/city
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/city/test_city_stage[1]_include.cmake")
include("/work/wt-survey/build2/tests/city/test_footprint_prism[1]_include.cmake")
include("/work/wt-survey/build2/tests/city/test_city_cli[1]_include.cmake")
include("/work/wt-survey/build2/tests/city/test_lods[1]_include.cmake")
include("/work/wt-survey/build2/tests/city/test_city_stream[1]_include.cmake")
