# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/reliability
# Build directory: /work/wt-survey/build2/tests/reliability
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/reliability/test_partition_stress[1]_include.cmake")
include("/work/wt-survey/build2/tests/reliability/test_fuzz_regressions[1]_include.cmake")
include("/work/wt-survey/build2/tests/reliability/test_fuzz_pipeline_regressions[1]_include.cmake")
include("/work/wt-survey/build2/tests/reliability/test_fuzz_extraction_regressions[1]_include.cmake")
