# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/report
# Build directory: /work/wt-survey/build2/tests/report
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/report/report_test[1]_include.cmake")
add_test([=[report_browser]=] "/usr/bin/python3" "/work/wt-survey/tests/report/browser_test.py" "/work/wt-survey/build2/hsr" "/work/wt-survey/build2/test_tmp/report_browser")
set_tests_properties([=[report_browser]=] PROPERTIES  SKIP_RETURN_CODE "77" TIMEOUT "900" _BACKTRACE_TRIPLES "/work/wt-survey/tests/report/CMakeLists.txt;6;add_test;/work/wt-survey/tests/report/CMakeLists.txt;0;")
