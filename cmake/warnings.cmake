# Project-wide warning and sanitizer flags, applied through an interface target.
add_library(mrf_flags INTERFACE)
target_compile_options(mrf_flags INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
  -Wno-sign-conversion)
if(MRF_WERROR)
  target_compile_options(mrf_flags INTERFACE -Werror)
endif()
if(MRF_NATIVE)
  target_compile_options(mrf_flags INTERFACE -march=native)
endif()
if(MRF_SANITIZE)
  target_compile_options(mrf_flags INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer)
  target_link_options(mrf_flags INTERFACE -fsanitize=address,undefined)
endif()
