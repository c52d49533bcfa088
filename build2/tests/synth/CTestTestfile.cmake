# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/synth
# Build directory: /work/wt-survey/build2/tests/synth
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/synth/synth_test[1]_include.cmake")
include("/work/wt-survey/build2/tests/synth/synth_eval_test[1]_include.cmake")
include("/work/wt-survey/build2/tests/synth/synth_aerial_test[1]_include.cmake")
include("/work/wt-survey/build2/tests/synth/synth_indoor_test[1]_include.cmake")
include("/work/wt-survey/build2/tests/synth/synth_office_test[1]_include.cmake")
