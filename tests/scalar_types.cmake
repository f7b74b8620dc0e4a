# The typed scalar suite, tests/test_scalar_types.cpp, as four executables
# test_scalar_types_<group> (NHDYN_SCALAR_GROUP: 1 float/double/long double, 2 multiprecision,
# 3 duals and AutoDiffScalar, 4 intervals), so that a parallel build compiles the groups side
# by side: together they instantiate every algorithm for eleven scalar types.
#
# Boost.Multiprecision's float128 needs libquadmath (GCC's own library, found by the compiler
# driver); without it nhdyn::quad falls back to the header-only cpp_bin_float_quad
# (scalar/multiprecision.hpp).
include(CheckCXXSourceCompiles)
set(CMAKE_REQUIRED_LIBRARIES quadmath)
check_cxx_source_compiles("#include <quadmath.h>
int main() { __float128 x = 2; return (int)sqrtq(x); }" NHDYN_HAVE_QUADMATH)
unset(CMAKE_REQUIRED_LIBRARIES)
foreach(group 1 2 3 4)
  nhdyn_add_test(test_scalar_types_${group} ${CMAKE_CURRENT_SOURCE_DIR}/test_scalar_types.cpp)
  target_compile_definitions(test_scalar_types_${group} PRIVATE NHDYN_SCALAR_GROUP=${group})
endforeach()
foreach(t test_scalar_types_2 test_linearize test_bounds)
  nhdyn_test_target(${t} _target)
  if(TARGET ${_target})
    if(NHDYN_HAVE_QUADMATH)
      target_link_libraries(${_target} PRIVATE quadmath)
    else()
      target_compile_definitions(${_target} PRIVATE NHDYN_NO_FLOAT128)
    endif()
  endif()
endforeach()
