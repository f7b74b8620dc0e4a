#pragma once
/// \file analysis/batch.hpp
/// Many states per call: the columns of n × K matrices, evaluated `simd_width` at a time by
/// the same generic kernels on the SIMD-pack scalar (scalar/simd.hpp) — 8 states per
/// evaluation with AVX-512, 4 with AVX2 —, the last group padded with its last state.
///
/// - `rne_batch(t)(Q, QD, QDD)`: τ of every column (n × K).
/// - `inverse_dynamics_batch(t, c)(Q, ETA, ETA_DOT)`: the nonholonomic inverse dynamics
///   (m × K): each state's lift and projection in double (with every check the constraint
///   makes on a state), rne in packs.
/// - `forward_dynamics_batch(t)(Q, QD, TAU)`: q̈ by the articulated-body algorithm in packs
///   (n × K); every articulated inertia checked lane by lane as aba(t) checks it.
///
/// Inputs are checked as the one-state calls check them (sizes, finite), and a bad column is
/// named. Results equal the one-state double calls to rounding (xsimd's sin and cos differ
/// from libm's in the last bit: tests/test_batch.cpp, ≤ 1e-13 relative).
#include <Eigen/Core>
#include <array>
#include <exception>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "../constraints/concept.hpp"
#include "../constraints/stages.hpp"
#include "../dynamics/aba.hpp"
#include "../dynamics/tree.hpp"
#include "../model/chain.hpp"
#include "../scalar/simd.hpp"

namespace nhdyn {

namespace detail {
/// Whether every entry is finite: detail::finite_range column by column (a vectorised test of
/// the exponent bits).
template <class X>
bool all_finite(const X& x) {
  for (Eigen::Index k = 0; k < x.cols(); ++k)
    if (!finite_range(x.col(k), 0, x.rows())) return false;
  return true;
}
/// Sizes (rows × same K) and finiteness of a batch argument, naming the first bad column.
template <class X>
void check_batch(const Eigen::MatrixBase<X>& x, int rows, Eigen::Index cols, const char* what, bool finite = true) {
  if (x.rows() != rows || x.cols() != cols) {
    std::ostringstream os;
    os << "batch argument " << what << " is " << x.rows() << " × " << x.cols() << ", expected " << rows << " × "
       << cols << " (one column per state)";
    throw input_error(os.str());
  }
  if (!finite || all_finite(x)) return;
  for (Eigen::Index k = 0; k < x.cols(); ++k)
    for (Eigen::Index i = 0; i < x.rows(); ++i)
      if (!std::isfinite(double(x(i, k)))) {
        std::ostringstream os;
        os << "batch argument " << what << ", state (column) " << k << ", entry " << i << " is " << double(x(i, k))
           << ": not finite";
        throw input_error(os.str());
      }
}
/// Columns k0 … k0 + W − 1 of x (the last column repeated past the end) into W-lane packs.
template <int W, class X, class P>
void pack_columns(const X& x, Eigen::Index k0, P& p) {
  const Eigen::Index last = x.cols() - 1;
  for (int l = 0; l < W; ++l) {
    const Eigen::Index k = std::min<Eigen::Index>(k0 + l, last);
    for (Eigen::Index i = 0; i < x.rows(); ++i) p(i)[l] = double(x(i, k));
  }
}
template <int W, class P, class Y>
void unpack_columns(const P& p, Eigen::Index k0, Y& y) {
  for (Eigen::Index i = 0; i < p.size(); ++i)
    for (int l = 0; l < W && k0 + l < y.cols(); ++l) y(i, k0 + l) = p(i)[l];
}
template <class Y>
void check_batch_result(const Y& y, const char* what) {
  if (all_finite(y)) return;
  for (Eigen::Index k = 0; k < y.cols(); ++k)
    for (Eigen::Index i = 0; i < y.rows(); ++i)
      if (!std::isfinite(y(i, k))) {
        std::ostringstream os;
        os << what << ": the result of state (column) " << k << ", entry " << i
           << " overflowed (not finite) although every input is finite";
        throw numerical_error(os.str());
      }
}
/// The batch loop: checks three n × K arguments (named), packs each group of W columns into
/// W-lane vectors a, b, c, calls f(k0, a, b, c, r) for the group's result r (n packs), and
/// returns the results' columns, checked finite.
template <int W, class A, class B, class C, class F>
Eigen::MatrixXd in_packs(int n, const A& a, const B& b, const C& c, const std::array<const char*, 3>& names,
                         const char* what, F&& f, bool b_finite = true) {
  const Eigen::Index K = a.cols();
  check_batch(a, n, K, names[0]);
  check_batch(b, n, K, names[1], b_finite);
  check_batch(c, n, K, names[2]);
  Eigen::MatrixXd out(n, K);
  Eigen::Matrix<simd_pack<W>, Eigen::Dynamic, 1> pa(n), pb(n), pc(n), r(n);
  for (Eigen::Index k0 = 0; k0 < K; k0 += W) {
    pack_columns<W>(a, k0, pa);
    pack_columns<W>(b, k0, pb);
    pack_columns<W>(c, k0, pc);
    f(k0, pa, pb, pc, r);
    unpack_columns<W>(r, k0, out);
  }
  check_batch_result(out, what);
  return out;
}
}  // namespace detail

/// τ of many states of a tree (see the file comment). W: the lanes per evaluation (a template
/// parameter, so that translation units built for different targets define different types).
template <int W = simd_width>
class rne_batch_fn {
 public:
  static constexpr int width = W;
  using pack = simd_pack<width>;

  explicit rne_batch_fn(const tree<double>& t, rne_options o = {})
      : links_(detail::make_tree_links(t)), g_(t.gravity()), n_(t.dof()), opt_(o) {}
  int dof() const { return n_; }

  template <class Q, class QD, class QDD>
  Eigen::MatrixXd operator()(const Eigen::MatrixBase<Q>& Q_, const Eigen::MatrixBase<QD>& QD_,
                             const Eigen::MatrixBase<QDD>& QDD_) const {
    const vec3<pack> g = g_.template cast<pack>();
    return detail::in_packs<width>(n_, Q_, QD_, QDD_, {"Q", "QD", "QDD"}, "rne_batch",
                                   [&](Eigen::Index, const auto& q, const auto& qd, const auto& qdd, auto& tau) {
                                     run(g, q, qd, qdd, tau);
                                   },
                                   opt_.velocity);  // without velocity terms q̇ is not read (as rne)
  }

 private:
  template <class P, class V>
  void run(const vec3<pack>& g, const P& q, const P& qd, const P& qdd, V& tau) const {
    if (opt_.gravity)
      opt_.velocity ? detail::tree_rne_kernel<true, true, pack>(links_, g, q, qd, qdd, tau)
                    : detail::tree_rne_kernel<true, false, pack>(links_, g, q, qd, qdd, tau);
    else
      opt_.velocity ? detail::tree_rne_kernel<false, true, pack>(links_, g, q, qd, qdd, tau)
                    : detail::tree_rne_kernel<false, false, pack>(links_, g, q, qd, qdd, tau);
  }
  std::vector<detail::tree_link<double>> links_;  // used by the pack kernel as they are
  vec3<double> g_;
  int n_;
  rne_options opt_;
};

inline rne_batch_fn<> rne_batch(const tree<double>& t, rne_options o = {}) { return rne_batch_fn<>(t, o); }
template <int N>
rne_batch_fn<> rne_batch(const chain<double, N>& c, rne_options o = {}) {
  return rne_batch_fn<>(as_tree(c), o);
}

/// The nonholonomic inverse dynamics of many states (see the file comment).
template <class C>
class inverse_dynamics_batch_fn {
 public:
  inverse_dynamics_batch_fn(const tree<double>& t, const C& c, rne_options o = {})
      : rne_(t, o), lift_(c), project_(c), c_(c) {
    if (c.dof() != t.dof())
      throw input_error("inverse_dynamics_batch: the constraint is for " + std::to_string(c.dof()) +
                        " joints, model '" + t.name() + "' has " + std::to_string(t.dof()));
  }

  template <class Q, class E, class ED>
  Eigen::MatrixXd operator()(const Eigen::MatrixBase<Q>& Q_, const Eigen::MatrixBase<E>& ETA,
                             const Eigen::MatrixBase<ED>& ETA_DOT) const {
    const int n = c_.dof(), m = c_.m();
    const Eigen::Index K = Q_.cols();
    detail::check_batch(Q_, n, K, "Q");
    detail::check_batch(ETA, m, K, "ETA");
    detail::check_batch(ETA_DOT, m, K, "ETA_DOT");
    Eigen::MatrixXd QD(n, K), QDD(n, K), out(m, K);
    vecN<double, C::n_at_compile_time> q(n);
    vecN<double, C::m_at_compile_time> e(m), ed(m);
    const auto at = [](Eigen::Index k, const std::exception& e) {
      return "inverse_dynamics_batch: state (column) " + std::to_string(k) + ": " + e.what();
    };
    for (Eigen::Index k = 0; k < K; ++k) {  // the lift, state by state
      q = Q_.col(k);
      e = ETA.col(k);
      ed = ETA_DOT.col(k);
      try {
        const auto xi = lift_(q, e, ed);
        QD.col(k) = xi.qd;
        QDD.col(k) = xi.qdd;
        if (!detail::finite_range(QD.col(k), 0, n) || !detail::finite_range(QDD.col(k), 0, n))
          throw numerical_error("the lifted q̇ or q̈ is not finite although every input is (overflow)");
      } catch (const input_error& x) {
        throw input_error(at(k, x));
      } catch (const numerical_error& x) {
        throw numerical_error(at(k, x));
      }
    }
    const Eigen::MatrixXd V = rne_(Q_, QD, QDD);
    vecN<double, C::n_at_compile_time> v(n);
    for (Eigen::Index k = 0; k < K; ++k) {  // the projection, state by state
      q = Q_.col(k);
      v = V.col(k);
      try {
        out.col(k) = project_(q, v);
      } catch (const input_error& x) {
        throw input_error(at(k, x));
      } catch (const numerical_error& x) {
        throw numerical_error(at(k, x));
      }
    }
    return out;
  }

 private:
  rne_batch_fn<> rne_;
  lift_fn<C> lift_;
  project_fn<C> project_;
  C c_;
};

template <class C>
  requires pfaffian_constraint<C>
inverse_dynamics_batch_fn<C> inverse_dynamics_batch(const tree<double>& t, const C& c, rne_options o = {}) {
  return inverse_dynamics_batch_fn<C>(t, c, o);
}

/// q̈ of many states by the articulated-body algorithm in packs (see the file comment).
template <int W = simd_width>
class forward_dynamics_batch_fn {
 public:
  static constexpr int width = W;
  using pack = simd_pack<width>;

  explicit forward_dynamics_batch_fn(const tree<double>& t)
      : links_(detail::make_tree_links(t)), g_(t.gravity()), n_(t.dof()), name_(t.name()) {
    for (int i = 0; i < n_; ++i) joints_.push_back(t[i].joint_name);
  }
  int dof() const { return n_; }

  template <class Q, class QD, class TAU>
  Eigen::MatrixXd operator()(const Eigen::MatrixBase<Q>& Q_, const Eigen::MatrixBase<QD>& QD_,
                             const Eigen::MatrixBase<TAU>& TAU_) const {
    const Eigen::Index K = Q_.cols();
    const vec3<pack> g = g_.template cast<pack>();
    return detail::in_packs<width>(
        n_, Q_, QD_, TAU_, {"Q", "QD", "TAU"}, "forward_dynamics_batch",
        [&](Eigen::Index k0, const auto& q, const auto& qd, const auto& tau, auto& qdd) {
          // aba(t)'s check of each articulated inertia D_i, lane by lane (a padded lane repeats a state)
          const auto check = [&](int i, const pack& D, const spatial::vec6<pack>& U, const spatial::vec6<pack>& S) {
            constexpr double tol = 64 * std::numeric_limits<double>::epsilon();
            for (int l = 0; l < width && k0 + l < K; ++l) {
              const double d = D[l];
              double u2 = 0, s2 = 0;
              for (int j = 0; j < 6; ++j) u2 += U(j)[l] * U(j)[l], s2 += S(j)[l] * S(j)[l];
              if (std::isfinite(d) && d > 0 && d * d > tol * tol * u2 * s2) continue;
              std::ostringstream os;
              os << "forward_dynamics_batch: model '" << name_ << "', state (column) " << k0 + l << ", joint '"
                 << joints_[static_cast<std::size_t>(i)] << "': the articulated inertia along the joint axis is D = "
                 << d << ", not positive against its scale (see aba): the forward dynamics is singular there";
              throw numerical_error(os.str());
            }
          };
          detail::tree_aba_kernel<pack>(links_, g, q, qd, tau, qdd, check);
        });
  }

 private:
  std::vector<detail::tree_link<double>> links_;  // used by the pack kernel as they are
  vec3<double> g_;
  int n_;
  std::string name_;
  std::vector<std::string> joints_;
};

inline forward_dynamics_batch_fn<> forward_dynamics_batch(const tree<double>& t) {
  return forward_dynamics_batch_fn<>(t);
}

}  // namespace nhdyn
