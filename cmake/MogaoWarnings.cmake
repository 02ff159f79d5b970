# SPDX-License-Identifier: Apache-2.0
# Warning and sanitizer flags for every mogao target: call mogao_target_defaults(<target>).
add_library(mogao_warnings INTERFACE)
target_compile_options(mogao_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)
if(MOGAO_WERROR)
  target_compile_options(mogao_warnings INTERFACE -Werror)
endif()
if(MOGAO_SANITIZE)
  target_compile_options(mogao_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
    -fno-sanitize-recover=undefined)
  target_link_options(mogao_warnings INTERFACE -fsanitize=address,undefined)
endif()
if(MOGAO_TSAN)
  if(MOGAO_SANITIZE)
    message(FATAL_ERROR "MOGAO_TSAN and MOGAO_SANITIZE cannot be combined (ThreadSanitizer excludes ASan)")
  endif()
  target_compile_options(mogao_warnings INTERFACE -fsanitize=thread -fno-omit-frame-pointer)
  target_link_options(mogao_warnings INTERFACE -fsanitize=thread)
endif()
# Fuzzing build (tests/fuzz, .ci/fuzz): clang only; every mogao library instrumented for libFuzzer's
# coverage and checked by ASan+UBSan (the fuzz executables add -fsanitize=fuzzer).
if(MOGAO_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "MOGAO_FUZZ needs clang (CC=clang CXX=clang++; see tests/fuzz/README.md)")
  endif()
  target_compile_options(mogao_warnings INTERFACE -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer
                                                  -fno-sanitize-recover=undefined)
  target_link_options(mogao_warnings INTERFACE -fsanitize=address,undefined)
endif()

function(mogao_target_defaults target)
  target_link_libraries(${target} PRIVATE mogao_warnings)
endfunction()
