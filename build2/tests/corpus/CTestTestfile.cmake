# CMake generated Testfile for 
# Source directory: /work/wt-survey/tests/corpus
# Build directory: /work/wt-survey/build2/tests/corpus
# 
# This file includes the relevant testing commands required for 
# testing this directory and lists subdirectories to be tested as well.
include("/work/wt-survey/build2/tests/corpus/test_corpus[1]_include.cmake")
