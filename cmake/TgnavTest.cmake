# tgnav_add_test(<file.cpp> <libs...> [PROPERTIES <ctest properties...>]): one GoogleTest
# executable per file, registered with CTest; PROPERTIES apply to every test case of the file
# (e.g. FIXTURES_REQUIRED scene_maps). The test name is the file's stem prefixed by its module
# folder (tests/harness/camera_test.cpp -> harness.camera_test); tests find models/ and configs/
# through TGNAV_SOURCE_DIR and share built feature maps through TGNAV_TEST_CACHE.
function(tgnav_add_test file)
  cmake_parse_arguments(ARG "" "" "PROPERTIES" ${ARGN})
  get_filename_component(stem ${file} NAME_WE)
  get_filename_component(module ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  set(target test_${module}_${stem})
  add_executable(${target} ${file})
  target_link_libraries(${target} PRIVATE ${ARG_UNPARSED_ARGUMENTS} GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE TGNAV_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
                                               TGNAV_TEST_CACHE="${PROJECT_BINARY_DIR}/test_cache")
  if(ARG_PROPERTIES)
    gtest_discover_tests(${target} TEST_PREFIX "${module}." DISCOVERY_TIMEOUT 60 PROPERTIES ${ARG_PROPERTIES})
  else()
    gtest_discover_tests(${target} TEST_PREFIX "${module}." DISCOVERY_TIMEOUT 60)
  endif()
endfunction()
