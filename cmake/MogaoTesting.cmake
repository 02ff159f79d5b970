# SPDX-License-Identifier: Apache-2.0
# mogao_add_gtest(<name> SOURCES <files...> LIBS <targets...> [LABELS <labels...>] [TIMEOUT <seconds, 300>])
# Builds a GoogleTest executable and registers each TEST with CTest (gtest_discover_tests).
# Tests that need ../shared/data get MOGAO_SCANS_DIR / MOGAO_MPCDI_DIR as compile definitions and call
# GTEST_SKIP() with a message when the folder is absent; the shared main (tests/support) then exits
# 77 and CTest reports those tests as skipped.
function(mogao_add_gtest name)
  if(NOT MOGAO_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(T "" "TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  if(NOT TARGET mogao_gtest_main)
    add_library(mogao_gtest_main STATIC ${PROJECT_SOURCE_DIR}/tests/support/gtest_main_skip77.cpp)
    target_link_libraries(mogao_gtest_main PUBLIC GTest::gtest)
  endif()
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_LIBS} mogao_gtest_main GTest::gtest)
  target_compile_definitions(${name} PRIVATE
    MOGAO_SCANS_DIR="${MOGAO_SCANS_DIR}" MOGAO_MPCDI_DIR="${MOGAO_MPCDI_DIR}"
    MOGAO_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  mogao_target_defaults(${name})
  if(NOT T_LABELS)
    set(T_LABELS unit)
  endif()
  gtest_discover_tests(${name} PROPERTIES SKIP_RETURN_CODE 77 DISCOVERY_TIMEOUT 60)
  # gtest_discover_tests splits list-valued properties, so a test would keep only its first label.
  # Set the labels after discovery instead: CTest runs this script after the discovered tests'
  # include file, which defines ${name}_TESTS.
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  set(labels_script ${CMAKE_CURRENT_BINARY_DIR}/${name}_labels.cmake)
  file(WRITE ${labels_script}
    "if(DEFINED ${name}_TESTS)\n"
    "  set_tests_properties(\${${name}_TESTS} PROPERTIES LABELS \"${T_LABELS}\" TIMEOUT ${T_TIMEOUT})\n"
    "endif()\n")
  set_property(DIRECTORY APPEND PROPERTY TEST_INCLUDE_FILES ${labels_script})
endfunction()
