# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/extraction
# Build directory: /work/wt-survey/build2/tests/extraction
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/extraction/test_extraction[1]_include.cmake")
include("/work/wt-survey/build2/tests/extraction/test_extraction_partition[1]_include.cmake")
