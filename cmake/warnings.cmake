# Project-wide warning, sanitizer and floating-point flags, applied through an interface target.
add_library(mrf_flags INTERFACE)
target_compile_options(mrf_flags INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
  -Wno-sign-conversion)
if(MRF_WERROR)
  target_compile_options(mrf_flags INTERFACE -Werror)
endif()
# sqrt need not set errno and floating-point operations need not trap
# (nothing reads errno or enables FP exceptions; NaN is detected by value):
# without these a sqrt is a call with a branch and a comparison cannot be
# turned into a mask, so the pair kernel's loop (dem_forces.cpp) does not
# vectorise. Neither flag changes a computed value.
target_compile_options(mrf_flags INTERFACE -fno-math-errno -fno-trapping-math)
if(MRF_NATIVE)
  target_compile_options(mrf_flags INTERFACE -march=native)
endif()
if(MRF_SANITIZE)
  # undefined behaviour stops the test that hit it (instead of a message in
  # the output of a test that passes, which ctest does not show)
  target_compile_options(mrf_flags INTERFACE -fsanitize=address,undefined -fno-sanitize-recover=undefined
                                             -fno-omit-frame-pointer)
  target_link_options(mrf_flags INTERFACE -fsanitize=address,undefined -fno-sanitize-recover=undefined)
endif()
