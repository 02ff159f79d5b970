# SPDX-License-Identifier: Apache-2.0
# Warning and sanitizer flags for every mogao target: call mogao_target_defaults(<target>).
add_library(mogao_warnings INTERFACE)
target_compile_options(mogao_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wno-sign-conversion)
if(MOGAO_WERROR)
  target_compile_options(mogao_warnings INTERFACE -Werror)
endif()
if(MOGAO_SANITIZE)
  target_compile_options(mogao_warnings INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  target_link_options(mogao_warnings INTERFACE -fsanitize=address,undefined)
endif()

function(mogao_target_defaults target)
  target_link_libraries(${target} PRIVATE mogao_warnings)
endfunction()
