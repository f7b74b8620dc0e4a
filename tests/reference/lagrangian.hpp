#pragma once
/// \file tests/reference/lagrangian.hpp
/// An independent Euler–Lagrange reference for serial standard-DH chains, for the tests only.
/// It shares no algorithm with the library: it reads a chain's data (the DH rows and rigid
/// bodies) and recomputes everything from first principles,
///
///     ⁰T_i = A_1 ⋯ A_i,  A_i = Rz(θ_i)·Tz(d_i)·Tx(a_i)·Rx(α_i)   (4×4 homogeneous, Spong eq. 3.10)
///     J_v,i = ∂p_ci/∂q,  J_ω,i = vee(∂R_i/∂q · R_iᵀ)              (exact, by dual numbers)
///     M(q) = Σ_i m_i J_v,iᵀ J_v,i + J_ω,iᵀ R_i I_i R_iᵀ J_ω,i        (Spong eq. 7.49)
///     c_ijk = ½ (∂M_ij/∂q_k + ∂M_ik/∂q_j − ∂M_jk/∂q_i)              (Christoffel, eq. 7.54)
///     g(q) = ∂P/∂q,  P = −Σ_i m_i gᵀ p_ci                          (eq. 7.58)
///     τ = M q̈ + C(q, q̇) q̇ + g(q)
///
/// Every derivative is exact: ∂M/∂q_k is M evaluated over nhdyn::dual (nested duals for
/// the Jacobians inside M), so the only error is rounding in the scalar T. Template on
/// T = long double to get a reference about 2000× more accurate than double.
///
/// Also: kinetic and potential energy, and the exact time derivative of the total energy
/// along a motion (q, q̇, q̈), for power-balance checks.
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <nhdyn/model/chain.hpp>
#include <nhdyn/scalar/dual.hpp>
#include <vector>

namespace nhdyn_ref {

template <class T>
using vec = Eigen::Matrix<T, Eigen::Dynamic, 1>;
template <class T>
using mat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>;
template <class T>
using vec3 = Eigen::Matrix<T, 3, 1>;
template <class T>
using mat3 = Eigen::Matrix<T, 3, 3>;
template <class T>
using mat4 = Eigen::Matrix<T, 4, 4>;

/// One DH row and its rigid body (com in frame i, inertia about the com in frame i's axes);
/// or, for a tree (`general`), a body whose frame is parent · X_PJ · joint(q) · X_JB, the joint
/// turning about or sliding along `axis` (4×4 homogeneous matrices, Rodrigues' formula: no
/// library code).
template <class T>
struct body {
  bool revolute = true;
  T alpha{0}, a{0}, theta{0}, d{0}, mass{0};
  vec3<T> com = vec3<T>::Zero();
  mat3<T> inertia = mat3<T>::Zero();
  bool general = false;
  int parent = -2;  // −2: the previous body (a chain); −1: the base; else a body index
  mat4<T> X_PJ = mat4<T>::Identity(), X_JB = mat4<T>::Identity();
  vec3<T> axis = vec3<T>(T(0), T(0), T(1));
};

/// A chain as the reference sees it.
template <class T>
struct model {
  std::vector<body<T>> bodies;
  vec3<T> gravity = vec3<T>::Zero();
  int dof() const { return static_cast<int>(bodies.size()); }
};

/// The data of an nhdyn chain, converted to T (no library algorithm is used).
template <class T, class S, int N>
model<T> from_chain(const nhdyn::chain<S, N>& c) {
  model<T> m;
  for (int i = 0; i < c.dof(); ++i) {
    const auto& L = c[i];
    body<T> b;
    b.revolute = L.joint == nhdyn::joint_type::revolute;
    b.alpha = T(L.alpha);
    b.a = T(L.a);
    b.theta = T(L.theta);
    b.d = T(L.d);
    b.mass = T(L.mass);
    for (int r = 0; r < 3; ++r) {
      b.com(r) = T(L.com(r));
      for (int k = 0; k < 3; ++k) b.inertia(r, k) = T(L.inertia(r, k));
    }
    m.bodies.push_back(b);
  }
  for (int r = 0; r < 3; ++r) m.gravity(r) = T(c.gravity()(r));
  return m;
}

/// The data of an nhdyn tree, converted to T (no library algorithm is used).
template <class T, class Tree>
model<T> from_tree(const Tree& t) {
  model<T> m;
  const auto hom = [](const auto& R, const auto& p) {
    mat4<T> X = mat4<T>::Identity();
    for (int r = 0; r < 3; ++r) {
      X(r, 3) = T(p(r));
      for (int k = 0; k < 3; ++k) X(r, k) = T(R(r, k));
    }
    return X;
  };
  for (int i = 0; i < t.dof(); ++i) {
    const auto& B = t[i];
    body<T> b;
    b.general = true;
    b.revolute = B.joint == nhdyn::joint_type::revolute;
    b.parent = B.parent;
    b.X_PJ = hom(B.R_PJ, B.p_PJ);
    b.X_JB = hom(B.R_JB, B.p_JB);
    for (int r = 0; r < 3; ++r) {
      b.axis(r) = T(B.axis(r));
      b.com(r) = T(B.com(r));
      for (int k = 0; k < 3; ++k) b.inertia(r, k) = T(B.inertia(r, k));
    }
    b.mass = T(B.mass);
    m.bodies.push_back(b);
  }
  for (int r = 0; r < 3; ++r) m.gravity(r) = T(t.gravity()(r));
  return m;
}

/// A value of the model scalar T as the computation scalar U (T, or duals over T).
template <class U, class T>
U lift(const T& x) {
  return U(x);
}

/// Homogeneous transform of link i at joint value qi: Rz(θ) Tz(d) Tx(a) Rx(α); for a tree
/// body X_PJ · joint(qi) · X_JB.
template <class U, class T>
mat4<U> dh_matrix(const body<T>& b, const U& qi) {
  using std::cos;
  using std::sin;
  if (b.general) {
    mat4<U> J = mat4<U>::Identity();
    const vec3<U> u(lift<U>(b.axis(0)), lift<U>(b.axis(1)), lift<U>(b.axis(2)));
    if (b.revolute) {  // Rodrigues: R = cos q 1 + sin q [u]x + (1 − cos q) u uᵀ
      mat3<U> K;
      K << U(0), -u(2), u(1), u(2), U(0), -u(0), -u(1), u(0), U(0);
      const U c = cos(qi), s = sin(qi);
      J.template block<3, 3>(0, 0) = c * mat3<U>::Identity() + s * K + (U(1) - c) * (u * u.transpose());
    } else {
      J.template block<3, 1>(0, 3) = u * qi;
    }
    const auto cast4 = [](const mat4<T>& X) {
      mat4<U> Y;
      for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) Y(r, k) = lift<U>(X(r, k));
      return Y;
    };
    return cast4(b.X_PJ) * J * cast4(b.X_JB);
  }
  const U th = b.revolute ? U(lift<U>(b.theta) + qi) : lift<U>(b.theta);
  const U d = b.revolute ? lift<U>(b.d) : U(lift<U>(b.d) + qi);
  const U ca = lift<U>(T(cos(b.alpha))), sa = lift<U>(T(sin(b.alpha)));
  mat4<U> Rz = mat4<U>::Identity(), Tz = mat4<U>::Identity(), Tx = mat4<U>::Identity(),
          Rx = mat4<U>::Identity();
  Rz(0, 0) = cos(th);
  Rz(0, 1) = -sin(th);
  Rz(1, 0) = sin(th);
  Rz(1, 1) = cos(th);
  Tz(2, 3) = d;
  Tx(0, 3) = lift<U>(b.a);
  Rx(1, 1) = ca;
  Rx(1, 2) = -sa;
  Rx(2, 1) = sa;
  Rx(2, 2) = ca;
  return Rz * Tz * Tx * Rx;
}

/// ⁰T_i for i = 0…n (entry 0 is the identity).
template <class U, class T>
std::vector<mat4<U>> poses(const model<T>& m, const vec<U>& q) {
  std::vector<mat4<U>> X(std::size_t(m.dof() + 1), mat4<U>::Identity());
  for (int i = 0; i < m.dof(); ++i) {
    const int parent = m.bodies[std::size_t(i)].parent == -2 ? i - 1 : m.bodies[std::size_t(i)].parent;
    X[std::size_t(i + 1)] = X[std::size_t(parent + 1)] * dh_matrix<U>(m.bodies[std::size_t(i)], q(i));
  }
  return X;
}

/// Position in frame 0 of point p of link i (1…n).
template <class U, class T>
vec3<U> point(const model<T>& m, const vec<U>& q, int i, const vec3<T>& p) {
  const mat4<U> X = poses<U>(m, q)[std::size_t(i)];
  vec3<U> r = X.template block<3, 1>(0, 3);
  for (int k = 0; k < 3; ++k) r += X.template block<3, 1>(0, k) * lift<U>(p(k));
  return r;
}

/// Velocity of every link's centre of mass and angular velocity of every link when
/// q moves along δ: v_i = d p_ci/dε, ω_i = vee(dR_i/dε R_iᵀ) at q + ε δ.
template <class U>
struct twist {
  vec3<U> v, w;
};
template <class U, class T>
std::vector<twist<U>> twists(const model<T>& m, const vec<U>& q, const vec<U>& delta) {
  using D = nhdyn::dual<U, 1>;
  const int n = m.dof();
  vec<D> qe(n);
  for (int j = 0; j < n; ++j) qe(j) = D(q(j), {delta(j)});
  const auto X = poses<D>(m, qe);
  std::vector<twist<U>> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto& Xi = X[std::size_t(i + 1)];
    const auto& b = m.bodies[std::size_t(i)];
    mat3<U> R, dR;
    vec3<U> dp;
    for (int r = 0; r < 3; ++r) {
      D p = Xi(r, 3);
      for (int k = 0; k < 3; ++k) p += Xi(r, k) * lift<D>(b.com(k));
      dp(r) = p.derivative(0);
      for (int k = 0; k < 3; ++k) {
        R(r, k) = Xi(r, k).value();
        dR(r, k) = Xi(r, k).derivative(0);
      }
    }
    const mat3<U> W = dR * R.transpose();  // skew(ω)
    out[std::size_t(i)].v = dp;
    out[std::size_t(i)].w = vec3<U>(U(0.5) * (W(2, 1) - W(1, 2)), U(0.5) * (W(0, 2) - W(2, 0)),
                                    U(0.5) * (W(1, 0) - W(0, 1)));
  }
  return out;
}

/// Rotation part of ⁰T_i, i = 1…n.
template <class U>
mat3<U> rotation(const mat4<U>& X) {
  return X.template block<3, 3>(0, 0);
}

/// Jacobians (3×n each) of link i's centre of mass and angular velocity, i = 1…n.
template <class U>
struct link_jacobian {
  mat<U> Jv, Jw;
};
template <class U, class T>
std::vector<link_jacobian<U>> jacobians(const model<T>& m, const vec<U>& q) {
  const int n = m.dof();
  std::vector<link_jacobian<U>> J(std::size_t(n), {mat<U>::Zero(3, n), mat<U>::Zero(3, n)});
  for (int j = 0; j < n; ++j) {
    vec<U> e = vec<U>::Zero(n);
    e(j) = U(1);
    const auto t = twists<U>(m, q, e);
    for (int i = 0; i < n; ++i) {
      J[std::size_t(i)].Jv.col(j) = t[std::size_t(i)].v;
      J[std::size_t(i)].Jw.col(j) = t[std::size_t(i)].w;
    }
  }
  return J;
}

/// M(q) = Σ m Jvᵀ Jv + Jωᵀ R I Rᵀ Jω.
template <class U, class T>
mat<U> mass_matrix(const model<T>& m, const vec<U>& q) {
  const int n = m.dof();
  const auto X = poses<U>(m, q);
  const auto J = jacobians<U>(m, q);
  mat<U> M = mat<U>::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    const auto& b = m.bodies[std::size_t(i)];
    const mat3<U> R = rotation<U>(X[std::size_t(i + 1)]);
    const mat3<U> I0 = R * b.inertia.template cast<U>() * R.transpose();
    const auto& Ji = J[std::size_t(i)];
    M += lift<U>(b.mass) * (Ji.Jv.transpose() * Ji.Jv) + Ji.Jw.transpose() * I0 * Ji.Jw;
  }
  return M;
}

/// ∂M/∂q_k for k = 0…n−1, exact (M over dual numbers).
template <class U, class T>
std::vector<mat<U>> mass_matrix_derivatives(const model<T>& m, const vec<U>& q) {
  using D = nhdyn::dual<U, 1>;
  const int n = m.dof();
  std::vector<mat<U>> dM;
  for (int k = 0; k < n; ++k) {
    vec<D> qk = q.template cast<D>();
    qk(k) = D::variable(q(k), 0);
    const mat<D> Mk = mass_matrix<D>(m, qk);
    mat<U> d(n, n);
    for (int r = 0; r < n; ++r)
      for (int c = 0; c < n; ++c) d(r, c) = Mk(r, c).derivative(0);
    dM.push_back(d);
  }
  return dM;
}

/// C(q, q̇) q̇ with C from the Christoffel symbols of M.
template <class U, class T>
vec<U> coriolis(const model<T>& m, const vec<U>& q, const vec<U>& qd) {
  const int n = m.dof();
  const auto dM = mass_matrix_derivatives<U>(m, q);
  vec<U> c = vec<U>::Zero(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        const U cijk = U(0.5) * (dM[std::size_t(k)](i, j) + dM[std::size_t(j)](i, k) -
                                 dM[std::size_t(i)](j, k));
        c(i) += cijk * qd(j) * qd(k);
      }
  return c;
}

/// Potential energy P(q) = −Σ m_i gᵀ p_ci.
template <class U, class T>
U potential_energy(const model<T>& m, const vec<U>& q) {
  const auto X = poses<U>(m, q);
  U P(0);
  for (int i = 0; i < m.dof(); ++i) {
    const auto& b = m.bodies[std::size_t(i)];
    const auto& Xi = X[std::size_t(i + 1)];
    for (int r = 0; r < 3; ++r) {
      U p = Xi(r, 3);
      for (int k = 0; k < 3; ++k) p += Xi(r, k) * lift<U>(b.com(k));
      P -= lift<U>(b.mass) * lift<U>(m.gravity(r)) * p;
    }
  }
  return P;
}

/// g(q) = ∂P/∂q, exact.
template <class U, class T>
vec<U> gravity(const model<T>& m, const vec<U>& q) {
  using D = nhdyn::dual<U, 1>;
  const int n = m.dof();
  vec<U> g(n);
  for (int k = 0; k < n; ++k) {
    vec<D> qk = q.template cast<D>();
    qk(k) = D::variable(q(k), 0);
    g(k) = potential_energy<D>(m, qk).derivative(0);
  }
  return g;
}

/// Kinetic energy Σ ½ m |v_c|² + ½ ωᵀ R I Rᵀ ω, from the link velocities (not from M).
template <class U, class T>
U kinetic_energy(const model<T>& m, const vec<U>& q, const vec<U>& qd) {
  const auto X = poses<U>(m, q);
  const auto t = twists<U>(m, q, qd);
  U K(0);
  for (int i = 0; i < m.dof(); ++i) {
    const auto& b = m.bodies[std::size_t(i)];
    const mat3<U> R = rotation<U>(X[std::size_t(i + 1)]);
    const vec3<U> w = t[std::size_t(i)].w, v = t[std::size_t(i)].v;
    const vec3<U> Iw = R * (b.inertia.template cast<U>() * (R.transpose() * w));
    K += U(0.5) * (lift<U>(b.mass) * v.dot(v) + w.dot(Iw));
  }
  return K;
}

/// E = K + P.
template <class U, class T>
U energy(const model<T>& m, const vec<U>& q, const vec<U>& qd) {
  return kinetic_energy<U>(m, q, qd) + potential_energy<U>(m, q);
}

/// dE/dt along the motion (q, q̇, q̈), exact: E at (q + ε q̇, q̇ + ε q̈).
template <class U, class T>
U energy_rate(const model<T>& m, const vec<U>& q, const vec<U>& qd, const vec<U>& qdd) {
  using D = nhdyn::dual<U, 1>;
  const int n = m.dof();
  vec<D> qe(n), qde(n);
  for (int j = 0; j < n; ++j) {
    qe(j) = D(q(j), {qd(j)});
    qde(j) = D(qd(j), {qdd(j)});
  }
  return energy<D>(m, qe, qde).derivative(0);
}

/// The three terms of the Euler–Lagrange equations at (q, q̇).
template <class U>
struct lagrangian_terms {
  mat<U> M;
  vec<U> c;  ///< C(q, q̇) q̇
  vec<U> g;  ///< g(q)
};
template <class U, class T>
lagrangian_terms<U> terms(const model<T>& m, const vec<U>& q, const vec<U>& qd) {
  return {mass_matrix<U>(m, q), coriolis<U>(m, q, qd), gravity<U>(m, q)};
}

/// τ = M q̈ + C q̇ + g (each term switchable, like nhdyn::rne_options).
template <class U, class T>
vec<U> inverse_dynamics(const model<T>& m, const vec<U>& q, const vec<U>& qd, const vec<U>& qdd,
                        bool with_gravity = true, bool with_velocity = true) {
  const auto L = terms<U>(m, q, qd);
  vec<U> tau = L.M * qdd;
  if (with_velocity) tau += L.c;
  if (with_gravity) tau += L.g;
  return tau;
}

}  // namespace nhdyn_ref
