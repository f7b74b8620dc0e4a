#pragma once
/// \file detail/attributes.hpp
/// Compiler attributes the kernels use, empty where the compiler has none.

/// Inline every call made inside the function (GCC, Clang): for a kernel built of many small
/// Eigen products that the compiler would otherwise leave as calls. Define NHDYN_NO_FLATTEN to
/// turn it off (the results are the same; the test programs do, for their compile time).
#if (defined(__GNUC__) || defined(__clang__)) && !defined(NHDYN_NO_FLATTEN)
#define NHDYN_FLATTEN __attribute__((flatten))
#else
#define NHDYN_FLATTEN
#endif

/// Inline this small helper into every kernel that calls it (GCC, Clang). Clang 14's flatten
/// inlines only the calls written in the flattened function itself, not the calls of the
/// functions it inlines: a kernel's per-body helper (kernel_placement, add_shifted_inertia) was
/// left as a call in every body's step. Off with NHDYN_NO_FLATTEN, as flatten is.
#if (defined(__GNUC__) || defined(__clang__)) && !defined(NHDYN_NO_FLATTEN)
#define NHDYN_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define NHDYN_ALWAYS_INLINE inline
#endif
