# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/io
# Build directory: /work/wt-survey/build2/tests/io
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/io/test_io[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_cityjson[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_raster[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_laz[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_laz_cli[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_las_writer[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_e57[1]_include.cmake")
include("/work/wt-survey/build2/tests/io/test_e57_cli[1]_include.cmake")
