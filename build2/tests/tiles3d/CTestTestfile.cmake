# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/tiles3d
# Build directory: /work/wt-survey/build2/tests/tiles3d
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/tiles3d/test_tiles3d[1]_include.cmake")
add_test([=[tiles3d_browser]=] "/usr/bin/python3" "/work/wt-survey/tests/tiles3d/tiles3d_browser_test.py" "/work/wt-survey/build2/hsr" "/work/wt-survey/build2/test_tmp/tiles3d_browser")
set_tests_properties([=[tiles3d_browser]=] PROPERTIES  SKIP_RETURN_CODE "77" TIMEOUT "900" _BACKTRACE_TRIPLES "/work/wt-survey/tests/tiles3d/CMakeLists.txt;6;add_test;/work/wt-survey/tests/tiles3d/CMakeLists.txt;0;")
