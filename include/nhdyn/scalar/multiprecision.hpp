#pragma once
/// \file scalar/multiprecision.hpp
/// Boost.Multiprecision scalars for nhdyn: reference computations and accuracy studies.
///
/// - `nhdyn::mp50`  — cpp_bin_float<50>: 50 decimal digits, binary, header-only.
/// - `nhdyn::dec50` — cpp_dec_float<50>: 50 decimal digits, decimal, header-only.
/// - `nhdyn::quad`  — IEEE binary128 (113-bit significand): Boost's `float128` over GCC's
///   __float128 when the compiler has it (link with -lquadmath, as tests/scalar_types.cmake
///   does), else the header-only cpp_bin_float_quad (define NHDYN_NO_FLOAT128).
///
/// Expression templates are off (`et_off`): Eigen and nhdyn's generic code store every
/// intermediate in the scalar type, and expression templates would only add copies.
/// The types work with nhdyn's default scalar_traits (value by static_cast<double>,
/// finiteness by boost::multiprecision::isfinite found by argument-dependent lookup);
/// Eigen::NumTraits come from <boost/multiprecision/eigen.hpp>.
///
/// Model constants given as double literals (π/2 in paper5's DH twists, 0.237 m…) enter a
/// 50-digit model rounded to double, exactly as the double model holds them: comparing a
/// double evaluation against the mp50 one measures the arithmetic's rounding error alone.
#include <boost/multiprecision/cpp_bin_float.hpp>
#include <boost/multiprecision/cpp_dec_float.hpp>
#include <boost/multiprecision/eigen.hpp>
#if defined(BOOST_HAS_FLOAT128) && !defined(NHDYN_NO_FLOAT128)
#include <boost/multiprecision/float128.hpp>
#define NHDYN_HAS_FLOAT128 1
#endif

#include "traits.hpp"

namespace nhdyn {

using mp50 = boost::multiprecision::number<boost::multiprecision::cpp_bin_float<50>,
                                           boost::multiprecision::et_off>;
using dec50 = boost::multiprecision::number<boost::multiprecision::cpp_dec_float<50>,
                                            boost::multiprecision::et_off>;
#ifdef NHDYN_HAS_FLOAT128
using quad = boost::multiprecision::number<boost::multiprecision::float128_backend,
                                           boost::multiprecision::et_off>;
#else
using quad = boost::multiprecision::number<
    boost::multiprecision::cpp_bin_float<113, boost::multiprecision::digit_base_2, void,
                                         std::int16_t, -16382, 16383>,
    boost::multiprecision::et_off>;
#endif

}  // namespace nhdyn
