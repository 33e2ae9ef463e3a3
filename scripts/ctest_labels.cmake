# Run by ctest after the GoogleTest discovery files (CMakeLists.txt adds it to the
# directory's TEST_INCLUDE_FILES last): gives the label "slow" to every discovered test
# whose full name contains "Slow" (a suite FooSlow, a test BarSlow, or a parameterised
# instance named so), so that `ctest -LE slow` leaves them out. `make test-sanitize` does
# that: under AddressSanitizer such tests would take too long for CI; `make test` runs all.
get_cmake_property(_lc_vars VARIABLES)
foreach(_lc_var IN LISTS _lc_vars)
  if(_lc_var MATCHES "^lc_.*_tests_TESTS$")
    foreach(_lc_test IN LISTS ${_lc_var})
      if(_lc_test MATCHES "Slow")
        set_tests_properties("${_lc_test}" PROPERTIES LABELS slow)
      endif()
    endforeach()
  endif()
endforeach()
