# CMake generated Testfile for 
# Source directory: /work/wt-survey/python
# Build directory: /work/wt-survey/build2/python
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
add_test([=[python_module]=] "/usr/bin/python3" "-m" "pytest" "-q" "-p" "no:cacheprovider" "/work/wt-survey/python/tests" "--ignore=/work/wt-survey/python/tests/test_batch.py" "--ignore=/work/wt-survey/python/tests/test_city.py")
set_tests_properties([=[python_module]=] PROPERTIES  ENVIRONMENT "PYTHONPATH=/work/wt-survey/build2/python;HSR_SHARED_DATA_DIR=/work/wt-survey/../shared/data;HSR_TEST_TMP_DIR=/work/wt-survey/build2/test_tmp/python" TIMEOUT "900" _BACKTRACE_TRIPLES "/work/wt-survey/python/CMakeLists.txt;38;add_test;/work/wt-survey/python/CMakeLists.txt;0;")
add_test([=[python_batch]=] "/usr/bin/python3" "-m" "pytest" "-q" "-p" "no:cacheprovider" "/work/wt-survey/python/tests/test_batch.py")
set_tests_properties([=[python_batch]=] PROPERTIES  ENVIRONMENT "PYTHONPATH=/work/wt-survey/build2/python;HSR_SHARED_DATA_DIR=/work/wt-survey/../shared/data;HSR_TEST_TMP_DIR=/work/wt-survey/build2/test_tmp/python" TIMEOUT "900" _BACKTRACE_TRIPLES "/work/wt-survey/python/CMakeLists.txt;42;add_test;/work/wt-survey/python/CMakeLists.txt;0;")
add_test([=[python_city]=] "/usr/bin/python3" "-m" "pytest" "-q" "-p" "no:cacheprovider" "/work/wt-survey/python/tests/test_city.py")
set_tests_properties([=[python_city]=] PROPERTIES  ENVIRONMENT "PYTHONPATH=/work/wt-survey/build2/python;HSR_SHARED_DATA_DIR=/work/wt-survey/../shared/data;HSR_TEST_TMP_DIR=/work/wt-survey/build2/test_tmp/python" TIMEOUT "900" _BACKTRACE_TRIPLES "/work/wt-survey/python/CMakeLists.txt;45;add_test;/work/wt-survey/python/CMakeLists.txt;0;")
