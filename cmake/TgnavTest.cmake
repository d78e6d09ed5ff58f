# tgnav_add_test(<file.cpp> <libs...>): one GoogleTest executable per file, registered with CTest.
# The test name is the file's stem prefixed by its module folder (tests/harness/camera_test.cpp
# -> harness.camera_test); tests find models/ and configs/ through TGNAV_SOURCE_DIR.
function(tgnav_add_test file)
  get_filename_component(stem ${file} NAME_WE)
  get_filename_component(module ${CMAKE_CURRENT_SOURCE_DIR} NAME)
  set(target test_${module}_${stem})
  add_executable(${target} ${file})
  target_link_libraries(${target} PRIVATE ${ARGN} GTest::gtest_main)
  target_compile_definitions(${target} PRIVATE TGNAV_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  gtest_discover_tests(${target} TEST_PREFIX "${module}." DISCOVERY_TIMEOUT 60)
endfunction()
