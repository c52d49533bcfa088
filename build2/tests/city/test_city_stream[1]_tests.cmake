add_test([=[CityStream.ThePlanOnTheKeptPointsIsThePlanOnTheWholeTile]=]  /work/wt-survey/build2/tests/city/test_city_stream [==[--gtest_filter=CityStream.ThePlanOnTheKeptPointsIsThePlanOnTheWholeTile]==] --gtest_also_run_disabled_tests)
set_tests_properties([=[CityStream.ThePlanOnTheKeptPointsIsThePlanOnTheWholeTile]=]  PROPERTIES WORKING_DIRECTORY /work/wt-survey/build2/tests/city SKIP_REGULAR_EXPRESSION [==[\[  SKIPPED \]]==] TIMEOUT 900)
set(  test_city_stream_TESTS CityStream.ThePlanOnTheKeptPointsIsThePlanOnTheWholeTile)
