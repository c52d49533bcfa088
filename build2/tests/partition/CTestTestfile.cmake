# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/partition
# Build directory: /work/wt-survey/build2/tests/partition
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/partition/test_partition[1]_include.cmake")
include("/work/wt-survey/build2/tests/partition/test_kinetic[1]_include.cmake")
include("/work/wt-survey/build2/tests/partition/test_growth_filters[1]_include.cmake")
include("/work/wt-survey/build2/tests/partition/test_partition_filters[1]_include.cmake")
