# Registers a GoogleTest executable's tests with ctest (run after each link, in script mode).
#
# One ctest test per gtest suite: one process runs the whole suite. Each process start costs
# 0.3-0.4 s here, nearly all of it the dynamic loader binding the ~260 shared libraries that
# Debian's OpenImageIO brings (OpenCV, GDAL, FFmpeg, ...); one process per test spent about five
# minutes of the suite's time on that alone. Suites whose names match PER_TEST_SUITES (the long
# renders) get one ctest test per test instead, run first (COST), so that `ctest -j2` keeps both cores
# busy to the end.
#
# Inputs (-D): TEST_EXECUTABLE, CTEST_FILE (written), WORKING_DIRECTORY, PER_TEST_SUITES (a regex),
# TIMEOUT (seconds per ctest test).
cmake_minimum_required(VERSION 3.25)
execute_process(COMMAND "${TEST_EXECUTABLE}" --gtest_list_tests
  OUTPUT_VARIABLE listing ERROR_VARIABLE errors RESULT_VARIABLE status TIMEOUT 60)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "${TEST_EXECUTABLE} --gtest_list_tests failed (${status}):\n${errors}")
endif()

# Drop the "# GetParam() = ..." comments (they can hold any characters), then read line by line:
# "Suite." opens a suite, "  Test" names one of its tests.
string(REGEX REPLACE "[ ]+#[^\n]*" "" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")

set(script "# Written by tests/register_with_ctest.cmake from `${TEST_EXECUTABLE} --gtest_list_tests`.\n")
set(suite "")
set(grouped_suites "")
foreach(line IN LISTS lines)
  if(line MATCHES "^([^ ]+)\\.$")
    set(suite "${CMAKE_MATCH_1}")
  elseif(line MATCHES "^  ([^ ]+)$" AND NOT suite STREQUAL "")
    set(test "${CMAKE_MATCH_1}")
    if(test MATCHES "^DISABLED_" OR suite MATCHES "(^|/)DISABLED_")
      continue()
    endif()
    if(suite MATCHES "${PER_TEST_SUITES}")
      set(name "${suite}.${test}")
      # A test that calls GTEST_SKIP is reported as skipped (only here: in a grouped suite one
      # skipped test must not hide the others' results).
      string(APPEND script
        "add_test([==[${name}]==] [==[${TEST_EXECUTABLE}]==] [==[--gtest_filter=${name}]==])\n"
        "set_tests_properties([==[${name}]==] PROPERTIES WORKING_DIRECTORY [==[${WORKING_DIRECTORY}]==]"
        " TIMEOUT ${TIMEOUT} COST 10 SKIP_REGULAR_EXPRESSION [==[\\[  SKIPPED \\]]==])\n")
    elseif(NOT suite IN_LIST grouped_suites)
      list(APPEND grouped_suites "${suite}")
      string(APPEND script
        "add_test([==[${suite}]==] [==[${TEST_EXECUTABLE}]==] [==[--gtest_filter=${suite}.*]==])\n"
        "set_tests_properties([==[${suite}]==] PROPERTIES WORKING_DIRECTORY [==[${WORKING_DIRECTORY}]==]"
        " TIMEOUT ${TIMEOUT})\n")
    endif()
  endif()
endforeach()
file(WRITE "${CTEST_FILE}" "${script}")
