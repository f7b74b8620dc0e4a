# Scalar-type tests: Boost.Multiprecision's float128 needs libquadmath (GCC's own library,
# found by the compiler driver); without it nhdyn::quad falls back to the header-only
# cpp_bin_float_quad (scalar/multiprecision.hpp).
include(CheckCXXSourceCompiles)
set(CMAKE_REQUIRED_LIBRARIES quadmath)
check_cxx_source_compiles("#include <quadmath.h>
int main() { __float128 x = 2; return (int)sqrtq(x); }" NHDYN_HAVE_QUADMATH)
unset(CMAKE_REQUIRED_LIBRARIES)
foreach(t test_scalar_types test_linearize test_bounds)
  if(TARGET ${t})
    if(NHDYN_HAVE_QUADMATH)
      target_link_libraries(${t} PRIVATE quadmath)
    else()
      target_compile_definitions(${t} PRIVATE NHDYN_NO_FLOAT128)
    endif()
  endif()
endforeach()
# The typed suite instantiates every algorithm for ten scalar types: -O1 keeps its compile
# time reasonable (interval soundness does not depend on the optimisation level: the
# rounding policy never changes the FPU mode).
if(TARGET test_scalar_types)
  target_compile_options(test_scalar_types PRIVATE -O1)
endif()
