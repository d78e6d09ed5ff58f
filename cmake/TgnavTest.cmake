# tgnav_add_test(<file.cpp> <libs...> [PROPERTIES <ctest properties...>]): one GoogleTest
# executable per file, registered with CTest; PROPERTIES apply to every test case of the file
# (e.g. FIXTURES_REQUIRED scene_maps). The test name is the file's stem prefixed by its module
# folder (tests/harness/camera_test.cpp -> harness.camera_test); tests find models/ and configs/
# through TGNAV_SOURCE_DIR and share built feature maps through TGNAV_TEST_CACHE.
#
# A test program's own code (assertions, fixtures, small reference computations) is compiled with
# less optimisation than the libraries it links: those keep the build type's flags (-O3), so the
# tests exercise the optimised code, and the GoogleTest-heavy test files compile faster
# (tests/harness/config_test.cpp: 33 s at -O3, 20 s at -O1 with g++ 12). Release builds only.
# Empty keeps the build type's flags, as the sanitizer build does: at -O0 there, its property
# tests' reference searches ran six to ten times slower than they saved in compiling.
if(TGNAV_SANITIZE)
  set(_tgnav_test_opt_default "")
else()
  set(_tgnav_test_opt_default -O1)
endif()
set(TGNAV_TEST_OPT "${_tgnav_test_opt_default}" CACHE STRING
    "Optimisation flag for the test programs' own sources in Release builds (empty: the build type's)")

function(tgnav_add_test file)
  cmake_parse_arguments(ARG "" "" "PROPERTIES" ${ARGN})
  get_filename_component(stem ${file} NAME_WE)
  get_filename_component(module ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  set(target test_${module}_${stem})
  add_executable(${target} ${file})
  target_link_libraries(${target} PRIVATE ${ARG_UNPARSED_ARGUMENTS} GTest::gtest_main)
  if(TGNAV_TEST_OPT)
    target_compile_options(${target} PRIVATE $<$<CONFIG:Release>:${TGNAV_TEST_OPT}>)
  endif()
  target_compile_definitions(${target} PRIVATE TGNAV_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                               TGNAV_TEST_CACHE="${PROJECT_BINARY_DIR}/test_cache")
  if(ARG_PROPERTIES)
    gtest_discover_tests(${target} TEST_PREFIX "${module}." DISCOVERY_TIMEOUT 60 PROPERTIES ${ARG_PROPERTIES})
  else()
    gtest_discover_tests(${target} TEST_PREFIX "${module}." DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
