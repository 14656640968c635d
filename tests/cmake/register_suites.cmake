# register_suites.cmake — run after a test binary is linked (tests/CMakeLists.txt): asks
# the binary for its tests (--gtest_list_tests) and writes OUT, a CTest file registering
# one test per GoogleTest suite, "<PREFIX><Suite>", that runs the binary on that suite.
#
# Why suites and not tests: every sylva process loads OpenImageIO's ~260 shared
# libraries, about 0.4 s a start (1 s under ASan), which one process per test paid 1,150
# times a build; one per suite pays it 190 times. A failing suite's output names the
# failing test (outputOnFailure), and `ctest -R room.Suite` still picks a suite.
#
# Inputs (-D): EXE (the test binary), PREFIX ("<room>."), OUT, TIMEOUT (seconds per
# suite), WORKDIR.
execute_process(COMMAND "${EXE}" --gtest_list_tests
                OUTPUT_VARIABLE listing ERROR_VARIABLE errors RESULT_VARIABLE rc TIMEOUT 60)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "${EXE} --gtest_list_tests failed (${rc}):\n${errors}")
endif()
# A suite's line starts in column 0 and ends its name with '.', perhaps followed by
# "  # TypeParam = ..."; its tests' lines are indented.
string(REGEX MATCHALL "(^|\n)[^ \n#][^ \n]*\\." suite_lines "${listing}")
set(text "# Written by tests/cmake/register_suites.cmake from ${EXE}; do not edit.\n")
set(count 0)
foreach(line IN LISTS suite_lines)
  string(STRIP "${line}" line)
  string(REGEX REPLACE "\\.$" "" suite "${line}")
  string(APPEND text
         "add_test([==[${PREFIX}${suite}]==] [==[${EXE}]==] [==[--gtest_filter=${suite}.*]==])\n"
         "set_tests_properties([==[${PREFIX}${suite}]==] PROPERTIES TIMEOUT ${TIMEOUT} "
         "WORKING_DIRECTORY [==[${WORKDIR}]==])\n")
  math(EXPR count "${count} + 1")
endforeach()
if(count EQUAL 0)
  message(FATAL_ERROR "${EXE} lists no test suites:\n${listing}")
endif()
file(WRITE "${OUT}.tmp" "${text}")
file(RENAME "${OUT}.tmp" "${OUT}")
