# roamlab_add_regression_suite(NAME SUITE.yaml [QUICK] [FILTER PATTERN] [BASELINE DIR] [JOBS J] [LABELS ...])
#
# Registers `roamlab regress SUITE.yaml --out <build>/regress/NAME` as the ctest test NAME: it fails when a check of
# the suite fails or a case errors, and leaves results.json and junit.xml (one testcase per check) in the output
# directory for CI to render. SUITE and BASELINE are relative to the calling CMakeLists.txt. QUICK runs only the
# cases marked `quick: true`, FILTER those whose name matches a glob. The test carries the label "regression" and
# LABELS. Works in roamlab's own tree and after find_package(roamlab), both through the target roamlab::roamlab.
function(roamlab_add_regression_suite name suite)
  cmake_parse_arguments(ARG "QUICK" "FILTER;BASELINE;JOBS" "LABELS" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "roamlab_add_regression_suite(${name}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT TARGET roamlab::roamlab)
    message(FATAL_ERROR "roamlab_add_regression_suite(${name}): no target roamlab::roamlab "
                        "(call find_package(roamlab) first)")
  endif()
  get_filename_component(suite_path "${suite}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT EXISTS "${suite_path}")
    message(FATAL_ERROR "roamlab_add_regression_suite(${name}): no suite file ${suite_path}")
  endif()
  set(command $<TARGET_FILE:roamlab::roamlab> regress "${suite_path}"
              --out "${CMAKE_CURRENT_BINARY_DIR}/regress/${name}" --quiet)
  if(ARG_QUICK)
    list(APPEND command --quick)
  endif()
  if(ARG_FILTER)
    list(APPEND command --filter "${ARG_FILTER}")
  endif()
  if(ARG_BASELINE)
    get_filename_component(baseline_path "${ARG_BASELINE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    list(APPEND command --baseline "${baseline_path}")
  endif()
  if(ARG_JOBS)
    list(APPEND command --jobs "${ARG_JOBS}")
  endif()
  add_test(NAME ${name} COMMAND ${command})
  set_tests_properties(${name} PROPERTIES LABELS "regression;${ARG_LABELS}")
endfunction()
