#pragma once
/// \file constraints/wheel_contacts.hpp
/// `wheel_contacts`: wheels touching a plane floor in 3D on any tree — a floating base
/// (model/floating.hpp: a wheeled-legged robot, a two-wheeled balancing base), a base whose
/// joints tilt its wheels, a planar base on its horizontal floor — as one Pfaffian constraint
/// read off the tree's kinematics. The one statement of wheeled_base, without its planar
/// shortcut: the rim point of a wheel in contact with the floor does not slip, and it stays on
/// the floor (docs/theory.md, "Wheels in 3D").
///
/// The floor is the plane n·(x − p₀) = 0, n its unit normal (up). A wheel's spin joint gives
/// its centre c and unit spin axis a (the joint's origin and axis, world). Its contact point is
/// the rim point lowest along n,
///
///     d = (n − (n·a) a) / |n − (n·a) a|,      P = c − r d                           (W.1)
///
/// (camber and pitch move P along the rim; a wheel lying flat, a ∥ n, has no lowest point and
/// is refused). At P: forward f = a × n / |a × n| (where a positive spin rolls the wheel),
/// lateral ℓ = n × f. With G(q) the Jacobian (3 × nv, world) of the wheel's material point at P,
/// the rows of A are
///
///     standard wheel (fixed, steered, castor):  ℓᵀG, fᵀG, nᵀG                       (W.2)
///     Swedish wheel, rollers at γ:              uᵀG (u = cos γ ℓ + sin γ f), nᵀG
///
/// The normal row is the velocity form of the holonomic n·(P(q) − p₀) = 0 (`gaps` reports the
/// left side; by the envelope theorem, d/dt of the lowest point's height is the material point's
/// normal velocity). λ of a row is the floor's force on the wheel along the row's unit vector
/// [N]: a negative normal λ is a floor that would have to pull (`pulling`).
///
/// Rows that vanish at every configuration (a planar base's normal rows: its joints hold the
/// height) are dropped, and named (`dropped_rows`). Rows that depend on others (four wheels'
/// normal rows on three free directions, two coaxial wheels' lateral rows) are kept, and λ is
/// the least-norm split among them (a statically indeterminate load: the minimum-norm
/// distribution, as whole-body controllers take it); S is built from an independent subset of
/// r = rank A rows (chosen at sampled configurations).
///
/// η = v_I for m = nv − r coordinates I (the `eta` option, or the rule: the r dependent ones D
/// are taken among the wheels' paths — legs and steering joints first, then the spins, then the
/// floating base's six — each kept where it raises the rank of A's D columns at sampled
/// configurations). S = [1 on I; −A_D⁻¹ A_I on D] and Ṡ(q, q̇) η = [0 on I; −A_D⁻¹ Ȧ(q, q̇) S η on
/// D], Ȧ(q, q̇) by one dual-number evaluation of A along the manifold (q ⊕ ε q̇). The input map E
/// selects the actuated joints (default: every joint but the floating base's six and the
/// castors' swivels and spins); τ solves SᵀE τ = Sᵀv with the least Σ w_j τ_j² (p > m: a
/// wheeled-legged robot's 16 actuators on its 10 η), or the call is refused naming the
/// direction of η that no actuator reaches (a balancing base's pitch).
///
/// This is the plain version: A dense from the kinematics' joint frames, a dense LU of A_D. A
/// planar base is wheeled_base's fast special case, tested equal.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "../detail/ldlt.hpp"
#include "../kinematics/tree.hpp"
#include "../model/floating.hpp"
#include "../scalar/dual.hpp"
#include "concept.hpp"
#include "wheeled_base.hpp"

namespace nhdyn {

/// A plane floor: its unit normal (up, out of the floor) and a point on it.
struct floor_plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  /// A ramp through `point` that rises at `angle` [rad] towards `heading` [rad, from the world's
  /// x axis about z]: n = cos(angle) e_z − sin(angle) (cos heading, sin heading, 0).
  static floor_plane slope(double angle, double heading = 0, Eigen::Vector3d point = Eigen::Vector3d::Zero()) {
    const Eigen::Vector3d h(std::cos(heading), std::sin(heading), 0);
    return {std::cos(angle) * Eigen::Vector3d::UnitZ() - std::sin(angle) * h, point};
  }
};

/// How wheel_contacts chooses η and τ, and where its floor is; empty lists take the defaults.
struct wheel_contacts_options {
  std::vector<std::string> eta{};       ///< the coordinates whose rates η holds (empty: the rule)
  std::vector<std::string> actuated{};  ///< the actuated joints, τ's order (empty: the default)
  std::vector<std::pair<std::string, double>> weights{};  ///< w_j > 0 of Σ w_j τ_j² (others 1)
  floor_plane floor{};
  /// Where warnings go (a dropped row); default: stderr, prefixed "nhdyn: warning: ".
  std::function<void(const std::string&)> warn{};
};

/// Which component of a contact point's velocity a row forbids.
enum class contact_row { lateral, rolling, roller, normal };

template <class Sc = double>
class wheel_contacts {
 public:
  using scalar_type = Sc;
  static constexpr int n_at_compile_time = dynamic;
  static constexpr int k_at_compile_time = dynamic;
  static constexpr int m_at_compile_time = dynamic;
  static constexpr int p_at_compile_time = dynamic;
  static constexpr bool orthonormal_S = false;

  wheel_contacts(const tree<Sc>& t, std::vector<wheel> wheels, wheel_contacts_options o = {})
      : kin_(t), floor_(std::move(o.floor)), nv_(t.dof()), nq_(t.nq()), names_(t.joint_names()),
        name_(t.name()) {
    const std::string at = "model '" + name_ + "', wheel_contacts: ";
    const double nn = floor_.normal.norm();
    if (!std::isfinite(nn) || nn < 1e-12 || !floor_.point.allFinite())
      throw model_error(at + "the floor's normal is zero or not finite, or its point is not finite");
    floor_.normal /= nn;
    if (wheels.empty()) throw model_error(at + "no wheels");
    for (std::size_t w = 0; w < wheels.size(); ++w) add_wheel(t, wheels[w], at + "wheels[" + std::to_string(w) + "] ");
    choose_rows(at, o.warn);
    choose_eta(at, o.eta);
    choose_actuation(at, o.actuated, o.weights);
  }

  int dof() const { return nv_; }
  int nq() const { return nq_; }
  /// The rows of A (every contact row kept; rank() of them independent).
  int k() const { return static_cast<int>(rows_.size()); }
  int rank() const { return static_cast<int>(ind_.size()); }
  int m() const { return static_cast<int>(I_.size()); }
  int p() const { return static_cast<int>(act_.size()); }
  const floor_plane& floor() const { return floor_; }

  /// A(q): k × nv, row by row as lambda_names() names them.
  template <class Q>
  auto A(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> a(k(), nv_);
    const auto K = kin_.joint_frames(q);
    for (std::size_t w = 0; w < wheels_.size(); ++w) {
      const auto c = contact_of<T>(K, w);
      const auto G = kin_.point_jacobian(K, wheels_[w].spin + 1, c.P);
      for (int r = 0; r < k(); ++r)
        if (rows_[std::size_t(r)].wheel == int(w)) a.row(r) = direction(c, rows_[std::size_t(r)].kind).transpose() * G;
    }
    return a;
  }
  /// n·(P − p₀) of each wheel [m]: how far its lowest rim point is above the floor.
  template <class Q>
  Eigen::VectorXd gaps(const Eigen::MatrixBase<Q>& q) const {
    const Eigen::Matrix3Xd P = contact_points(q);
    return (floor_.normal.transpose() * P).transpose().array() - floor_.normal.dot(floor_.point);
  }
  /// The contact points P (world), one column per wheel.
  template <class Q>
  Eigen::Matrix3Xd contact_points(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    const auto K = kin_.joint_frames(q);
    Eigen::Matrix3Xd P(3, static_cast<Eigen::Index>(wheels_.size()));
    for (std::size_t w = 0; w < wheels_.size(); ++w) {
      const auto c = contact_of<T>(K, w);
      for (int i = 0; i < 3; ++i) P(i, Eigen::Index(w)) = value_of(c.P(i));
    }
    return P;
  }

  /// S(q): nv × m, η's coordinates' unit columns and −A_D⁻¹ A_I on D.
  template <class Q>
  auto S(const Eigen::MatrixBase<Q>& q) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    const auto a = A(q);
    const auto lu = factor_D<T>(a);
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> s = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>::Zero(nv_, m());
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> AI(rank(), m());
    for (int c = 0; c < m(); ++c) {
      s(I_[std::size_t(c)], c) = T(1);
      for (int r = 0; r < rank(); ++r) AI(r, c) = a(ind_[std::size_t(r)], I_[std::size_t(c)]);
    }
    const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> x = lu.solve(AI);
    for (int c = 0; c < m(); ++c)
      for (int r = 0; r < rank(); ++r) s(D_[std::size_t(r)], c) = -x(r, c);
    return s;
  }
  template <class Q, class E>
  auto S_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<E>& eta) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename E::Scalar>;
    return Eigen::Matrix<T, Eigen::Dynamic, 1>(S(q).template cast<T>() * eta.template cast<T>());
  }
  /// Ṡ(q, q̇) η = [0 on I; −A_D⁻¹ Ȧ(q, q̇) S(q) η on D] (the file comment), Ȧ(q, q̇) by duals of
  /// A along q ⊕ ε q̇.
  template <class Q, class QD, class E>
  auto Sdot_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd, const Eigen::MatrixBase<E>& eta) const {
    using T = promote_t<promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>, typename E::Scalar>;
    const Eigen::Matrix<T, Eigen::Dynamic, 1> w = S_times(q, eta).template cast<T>();
    const Eigen::Matrix<T, Eigen::Dynamic, 1> Adot_w = A_dot_times<T>(q, qd, w);
    const auto lu = factor_D<T>(A(q).template cast<T>());
    Eigen::Matrix<T, Eigen::Dynamic, 1> b(rank());
    for (int r = 0; r < rank(); ++r) b(r) = Adot_w(ind_[std::size_t(r)]);
    const Eigen::Matrix<T, Eigen::Dynamic, 1> x = lu.solve(b);
    Eigen::Matrix<T, Eigen::Dynamic, 1> out = Eigen::Matrix<T, Eigen::Dynamic, 1>::Zero(nv_);
    for (int r = 0; r < rank(); ++r) out(D_[std::size_t(r)]) = -x(r);
    return out;
  }
  template <class Q, class QD>
  auto Sdot(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename QD::Scalar>;
    return detail::columns_of<T, dynamic, dynamic>(nv_, m(), [&](const auto& e) { return Sdot_times(q, qd, e); });
  }
  /// Ȧ(q, q̇) w (k entries): d/dε A(q ⊕ ε q̇) w at ε = 0.
  template <class T, class Q, class QD, class W>
  Eigen::Matrix<T, Eigen::Dynamic, 1> A_dot_times(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<QD>& qd,
                                                  const W& w) const {
    using D = dual<T, 1>;
    const Eigen::Matrix<D, Eigen::Dynamic, 1> step = qd.template cast<T>().template cast<D>() * D::variable(T(0), 0);
    const auto qe = integrate(kin_.model(), q.template cast<T>().eval(), step);
    const auto a = A(qe);
    Eigen::Matrix<T, Eigen::Dynamic, 1> out = Eigen::Matrix<T, Eigen::Dynamic, 1>::Zero(k());
    for (int r = 0; r < k(); ++r)
      for (int j = 0; j < nv_; ++j) out(r) += a(r, j).derivative(0) * w(j);
    return out;
  }

  /// E(q): nv × p, the actuated joints' unit columns.
  template <class Q>
  auto E(const Eigen::MatrixBase<Q>&) const {
    using T = promote_t<Sc, typename Q::Scalar>;
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> e = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>::Zero(nv_, p());
    for (int c = 0; c < p(); ++c) e(act_[std::size_t(c)], c) = T(1);
    return e;
  }
  /// τ with SᵀE τ = r (m rows; a vector or columns), of least Σ w_j τ_j²: τ = W⁻¹Gᵀ(GW⁻¹Gᵀ)⁻¹ r,
  /// G = SᵀE. Refused (numerical_error) where G has not full row rank: the direction of η that
  /// no actuator reaches is named.
  template <class Q, class R>
  auto solve_actuation(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<R>& r) const {
    using T = promote_t<promote_t<Sc, typename Q::Scalar>, typename R::Scalar>;
    const auto s = S(q);
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> G(m(), p()), GW(m(), p());
    for (int c = 0; c < p(); ++c) {
      G.col(c) = s.row(act_[std::size_t(c)]).transpose().template cast<T>();
      GW.col(c) = G.col(c) / T(w_[std::size_t(c)]);
    }
    const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> N = GW * G.transpose();
    check_reach(N);
    const Eigen::Matrix<T, Eigen::Dynamic, R::ColsAtCompileTime> y =
        ldlt_factor<T, dynamic>(N, "SᵀE W⁻¹ EᵀS").solve(r.template cast<T>().eval());
    return Eigen::Matrix<T, Eigen::Dynamic, R::ColsAtCompileTime>(GW.transpose() * y);
  }
  /// λ, the least-norm solution of Aᵀλ = v − Eτ (k entries, as lambda_names() names them), from
  /// the independent rows (the file comment): the constraint_forces stage's.
  template <class Q, class V, class Tau, class L>
  void lambda_into(const Eigen::MatrixBase<Q>& q, const Eigen::MatrixBase<V>& v, const Tau& tau, L& lambda) const {
    using T = typename L::Scalar;
    const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> a = A(q).template cast<T>();
    Eigen::Matrix<T, Eigen::Dynamic, 1> res = v.template cast<T>();
    for (int c = 0; c < p(); ++c) res(act_[std::size_t(c)]) -= T(tau(c));
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> Ai(rank(), nv_);
    for (int r = 0; r < rank(); ++r) Ai.row(r) = a.row(ind_[std::size_t(r)]);
    const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> AAi = Ai * Ai.transpose();
    const auto f = ldlt_factor<T, dynamic>(AAi, "the independent contact rows' AAᵀ");
    const Eigen::Matrix<T, Eigen::Dynamic, 1> li = f.solve(Eigen::Matrix<T, Eigen::Dynamic, 1>(Ai * res));
    lambda.resize(k());
    if (rank() == k()) {
      for (int r = 0; r < rank(); ++r) lambda(ind_[std::size_t(r)]) = li(r);
      return;
    }
    // every row is C·(independent rows), C = A Aᵢᵀ (Aᵢ Aᵢᵀ)⁻¹; the least-norm λ is C (CᵀC)⁻¹ λᵢ
    const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> C =
        f.solve(Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>(Ai * a.transpose())).transpose();
    const Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> CtC = C.transpose() * C;
    lambda = C * ldlt_factor<T, dynamic>(CtC, "CᵀC").solve(li);
  }
  /// The wheels whose normal force λ is negative (beyond 1e-9 of the largest |λ|): where the
  /// floor would have to pull. λ as lambda_into gives it.
  template <class L>
  std::vector<std::string> pulling(const L& lambda) const {
    std::vector<std::string> out;
    double scale = 0;
    for (Eigen::Index i = 0; i < lambda.size(); ++i) scale = std::max(scale, std::abs(value_of(lambda(i))));
    for (int r = 0; r < k(); ++r)
      if (rows_[std::size_t(r)].kind == contact_row::normal && value_of(lambda(r)) < -1e-9 * scale)
        out.push_back(wheels_[std::size_t(rows_[std::size_t(r)].wheel)].name);
    return out;
  }

  std::vector<std::string> eta_names(const std::vector<std::string>& joints) const { return pick(joints, I_); }
  std::vector<std::string> tau_names(const std::vector<std::string>& joints) const { return pick(joints, act_); }
  /// "<spin joint>.lateral" / ".rolling" / ".roller" / ".normal", A's rows in order.
  std::vector<std::string> lambda_names() const {
    std::vector<std::string> out;
    for (const auto& r : rows_) out.push_back(wheels_[std::size_t(r.wheel)].name + "." + row_name(r.kind));
    return out;
  }
  /// The rows dropped because they vanish at every configuration, named as lambda_names().
  const std::vector<std::string>& dropped_rows() const { return dropped_; }
  /// The coordinates whose rates are not in η (D, A_D's columns), by name.
  std::vector<std::string> dependent_names() const { return pick(names_, D_); }
  bool depends_on(int j) const { return on_path_[std::size_t(j)]; }
  const tree<Sc>& model() const { return kin_.model(); }

 private:
  struct wheel_data {
    std::string name;  ///< the spin joint's
    wheel_kind kind;
    int spin = -1, steer = -1;
    double radius = 0, gamma = 0;
  };
  struct row {
    int wheel;
    contact_row kind;
  };
  template <class T>
  struct contact {
    vec3<T> P, l, f, n;
    T cg, sg;  ///< the rollers' cos γ, sin γ
  };

  static const char* row_name(contact_row r) {
    switch (r) {
      case contact_row::lateral: return "lateral";
      case contact_row::rolling: return "rolling";
      case contact_row::roller: return "roller";
      case contact_row::normal: return "normal";
    }
    return "?";
  }
  template <class T>
  static vec3<T> direction(const contact<T>& c, contact_row r) {
    switch (r) {
      case contact_row::lateral: return c.l;
      case contact_row::rolling: return c.f;
      case contact_row::roller: return vec3<T>(c.cg * c.l + c.sg * c.f);
      case contact_row::normal: return c.n;
    }
    return c.n;
  }
  /// (W.1) and the contact frame of wheel w from the joint frames K.
  template <class T>
  contact<T> contact_of(const std::vector<pose<T>>& K, std::size_t w) const {
    using std::sqrt;
    const auto& wh = wheels_[w];
    const vec3<T> c = K[std::size_t(wh.spin)].p, a = K[std::size_t(wh.spin)].R.col(2);
    contact<T> out;
    out.n = floor_.normal.template cast<T>();
    const vec3<T> dn = out.n - a.dot(out.n) * a;
    const T len = sqrt(dn.dot(dn));
    if (!(value_of(len) > 1e-9))
      throw numerical_error("wheel_contacts: wheel '" + wh.name + "' lies flat on the floor (its spin axis along the "
                            "floor's normal): it has no lowest rim point");
    out.P = c - (T(wh.radius) / len) * dn;
    const vec3<T> an = a.cross(out.n);
    out.f = an / sqrt(an.dot(an));  // |a × n| = |dn| = len
    out.l = out.n.cross(out.f);
    out.cg = T(std::cos(wh.gamma));
    out.sg = T(std::sin(wh.gamma));
    return out;
  }
  /// A_D (the independent rows, D's columns) of a, factored.
  template <class T, class AM>
  Eigen::PartialPivLU<Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>> factor_D(const AM& a) const {
    Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic> AD(rank(), rank());
    for (int r = 0; r < rank(); ++r)
      for (int c = 0; c < rank(); ++c) AD(r, c) = T(a(ind_[std::size_t(r)], D_[std::size_t(c)]));
    Eigen::PartialPivLU<Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic>> lu(AD);
    double scale = 0, det = std::abs(value_of(T(lu.determinant())));
    for (int r = 0; r < rank(); ++r)
      for (int c = 0; c < rank(); ++c) scale = std::max(scale, std::abs(value_of(AD(r, c))));
    // the smallest pivot of U against the largest entry
    double piv = INFINITY;
    const auto& U = lu.matrixLU();
    for (int i = 0; i < rank(); ++i) piv = std::min(piv, std::abs(value_of(T(U(i, i)))));
    if (rank() > 0 && !(piv > 1e-10 * scale && det > 0))
      throw numerical_error("wheel_contacts: model '" + name_ + "': the contact rows cannot be solved for the dependent "
                            "coordinates (" + join(pick(names_, D_)) + ") at this configuration (a singular leg or "
                            "steering); give other ones in \"eta\"");
    return lu;
  }
  template <class N>
  void check_reach(const N& Nm) const {
    Eigen::MatrixXd Nd(Nm.rows(), Nm.cols());
    for (Eigen::Index i = 0; i < Nm.size(); ++i) Nd.data()[i] = value_of(Nm.data()[i]);
    if (m() == 0) return;
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Nd);
    const double top = es.eigenvalues().maxCoeff();
    if (es.eigenvalues()(0) > 1e-12 * top && top > 0) return;
    const Eigen::VectorXd y = es.eigenvectors().col(0);
    std::ostringstream os;
    os << "wheel_contacts: model '" << name_ << "': the actuators (" << join(pick(names_, act_))
       << ") cannot produce the motion along eta = (";
    bool first = true;
    for (int i = 0; i < m(); ++i)
      if (std::abs(y(i)) > 1e-6) {
        os << (first ? "" : ", ") << std::setprecision(3) << y(i) << " " << names_[std::size_t(I_[std::size_t(i)])];
        first = false;
      }
    os << "): S^T E has rank below m = " << m() << " (an unactuated direction, as a balancing base's pitch)";
    throw numerical_error(os.str());
  }

  int index_of(const std::string& joint, const std::string& at) const {
    for (int i = 0; i < nv_; ++i)
      if (names_[std::size_t(i)] == joint) return i;
    throw model_error(at + "no joint named '" + joint + "' (joints: " + join(names_) + ")");
  }
  void add_wheel(const tree<Sc>& t, const wheel& w, const std::string& at) {
    wheel_data d;
    d.name = w.spin;
    d.kind = w.kind;
    d.spin = index_of(w.spin, at + "spin: ");
    if (t[d.spin].joint != joint_type::revolute || t[d.spin].free_flyer)
      throw model_error(at + "spin joint '" + w.spin + "' is not a revolute joint");
    if (!(w.radius > 0)) throw model_error(at + "the radius must be positive");
    d.radius = w.radius;
    if (w.kind == wheel_kind::steered || w.kind == wheel_kind::castor) {
      d.steer = index_of(w.steer, at + (w.kind == wheel_kind::castor ? "swivel: " : "steer: "));
      if (!t.supports(d.steer, d.spin))
        throw model_error(at + "joint '" + w.steer + "' does not carry the wheel '" + w.spin + "'");
    }
    if (w.kind == wheel_kind::swedish) {
      if (!(std::abs(w.roller_angle) > 0 && std::abs(w.roller_angle) <= std::numbers::pi / 2 + 1e-12))
        throw model_error(at + "the rollers' angle must be within ±90° and not 0");
      d.gamma = w.roller_angle;
    }
    for (const auto& o : wheels_)
      if (o.spin == d.spin) throw model_error(at + "spin joint '" + w.spin + "' belongs to another wheel too");
    wheels_.push_back(d);
  }

  /// Configurations to sample A at: the joints at random within half their range (±π/2, or
  /// their limits), a floating root upright on the floor (its z axis along the floor's normal)
  /// at a random heading — the attitude the robot has when its wheels touch, so that the
  /// dependent coordinates chosen there can be solved for where the robot stands (a choice
  /// made at random attitudes can be singular upright). Seeded: the choices are reproducible.
  std::vector<Eigen::VectorXd> samples() const {
    std::mt19937_64 rng(20261207);
    std::uniform_real_distribution<double> heading(-std::numbers::pi, std::numbers::pi);
    const Eigen::Quaterniond up = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), floor_.normal);
    std::vector<Eigen::VectorXd> out;
    for (int s = 0; s < 3; ++s) {
      Eigen::VectorXd q = random_configuration(kin_.model(), rng);
      const bool ff = kin_.model().floating();
      for (int i = ff ? 6 : 0; i < nv_; ++i) q(i + (ff ? 1 : 0)) *= 0.5;  // the joints nearer their zero
      if (ff)
        q.segment<4>(3) = (up * Eigen::Quaterniond(Eigen::AngleAxisd(heading(rng), Eigen::Vector3d::UnitZ()))).coeffs();
      out.push_back(std::move(q));
    }
    return out;
  }
  static Eigen::MatrixXd value_matrix(const auto& a) {
    Eigen::MatrixXd d(a.rows(), a.cols());
    for (Eigen::Index i = 0; i < a.size(); ++i) d.data()[i] = value_of(a.data()[i]);
    return d;
  }
  static int rank_of(const Eigen::MatrixXd& a) {
    if (a.size() == 0) return 0;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(a);
    lu.setThreshold(1e-9);
    return int(lu.rank());
  }
  void choose_rows(const std::string& at, const std::function<void(const std::string&)>& warn) {
    std::vector<row> all;
    for (int w = 0; w < int(wheels_.size()); ++w) {
      if (wheels_[std::size_t(w)].kind == wheel_kind::swedish) {
        all.push_back({w, contact_row::roller});
      } else {
        all.push_back({w, contact_row::lateral});
        all.push_back({w, contact_row::rolling});
      }
      all.push_back({w, contact_row::normal});
    }
    rows_ = all;
    std::vector<Eigen::MatrixXd> As;
    for (const auto& q : samples()) As.push_back(value_matrix(A(q)));
    std::vector<row> kept;
    std::vector<int> kept_index;
    for (int r = 0; r < int(all.size()); ++r) {
      double size = 0;
      for (const auto& a : As) size = std::max(size, a.row(r).cwiseAbs().maxCoeff());
      if (size > 1e-12) {
        kept.push_back(all[std::size_t(r)]);
        kept_index.push_back(r);
      } else {
        dropped_.push_back(wheels_[std::size_t(all[std::size_t(r)].wheel)].name + "." + row_name(all[std::size_t(r)].kind));
      }
    }
    if (!dropped_.empty()) {
      const std::string msg = at + "rows that vanish at every configuration are dropped: " + join(dropped_);
      if (warn) warn(msg);
    }
    rows_ = kept;
    // the independent subset: a row joins while it raises the rank at every sample
    for (int r = 0; r < k(); ++r) {
      std::vector<int> trial = ind_;
      trial.push_back(r);
      bool raises = true;
      for (const auto& a : As) {
        Eigen::MatrixXd sub(trial.size(), nv_);
        for (std::size_t i = 0; i < trial.size(); ++i) sub.row(Eigen::Index(i)) = a.row(kept_index[std::size_t(trial[i])]);
        if (rank_of(sub) < int(trial.size())) raises = false;
      }
      if (raises) ind_ = trial;
    }
  }
  void choose_eta(const std::string& at, const std::vector<std::string>& eta) {
    on_path_.assign(std::size_t(nv_), false);
    for (const auto& w : wheels_)
      for (int j = w.spin; j >= 0; j = kin_.model().parent(j)) on_path_[std::size_t(j)] = true;
    std::vector<Eigen::MatrixXd> As;
    for (const auto& q : samples()) {
      const Eigen::MatrixXd a = value_matrix(A(q));
      Eigen::MatrixXd ai(rank(), nv_);
      for (int r = 0; r < rank(); ++r) ai.row(r) = a.row(ind_[std::size_t(r)]);
      As.push_back(ai);
    }
    const auto raises = [&](const std::vector<int>& cols) {
      for (const auto& a : As) {
        Eigen::MatrixXd sub(rank(), cols.size());
        for (std::size_t i = 0; i < cols.size(); ++i) sub.col(Eigen::Index(i)) = a.col(cols[i]);
        if (rank_of(sub) < int(cols.size())) return false;
      }
      return true;
    };
    if (!eta.empty()) {
      std::vector<bool> in(std::size_t(nv_), false);
      for (const auto& e : eta) {
        const int j = index_of(e, at + "eta: ");
        if (in[std::size_t(j)]) throw model_error(at + "eta names '" + e + "' twice");
        in[std::size_t(j)] = true;
        I_.push_back(j);
      }
      for (int j = 0; j < nv_; ++j)
        if (!in[std::size_t(j)]) D_.push_back(j);
      if (int(D_.size()) != rank() || !raises(D_))
        throw model_error(at + "eta (" + join(eta) + ") leaves " + std::to_string(D_.size()) + " coordinates (" +
                          join(pick(names_, D_)) + ") that the " + std::to_string(rank()) +
                          " independent contact rows cannot determine: eta needs " + std::to_string(nv_ - rank()) +
                          " entries whose complement A's rows solve for");
      return;
    }
    // the rule: legs and steering first, then the spins, then the floating base's six
    std::vector<int> order;
    const auto is_spin = [&](int j) {
      for (const auto& w : wheels_)
        if (w.spin == j) return true;
      return false;
    };
    for (int pass = 0; pass < 3; ++pass)
      for (int j = nv_ - 1; j >= 0; --j) {
        if (!on_path_[std::size_t(j)]) continue;
        const bool ff = kin_.model()[j].free_flyer, spin = is_spin(j);
        if ((pass == 0 && !ff && !spin) || (pass == 1 && spin) || (pass == 2 && ff)) order.push_back(j);
      }
    for (int j : order) {
      if (int(D_.size()) == rank()) break;
      std::vector<int> trial = D_;
      trial.push_back(j);
      if (raises(trial)) D_ = trial;
    }
    if (int(D_.size()) != rank())
      throw model_error(at + "the contact rows cannot be solved for any set of the wheels' joints");
    std::sort(D_.begin(), D_.end());
    for (int j = 0; j < nv_; ++j)
      if (std::find(D_.begin(), D_.end(), j) == D_.end()) I_.push_back(j);
  }
  void choose_actuation(const std::string& at, const std::vector<std::string>& actuated,
                        const std::vector<std::pair<std::string, double>>& weights) {
    if (!actuated.empty()) {
      for (const auto& a : actuated) {
        const int j = index_of(a, at + "actuated: ");
        if (std::find(act_.begin(), act_.end(), j) != act_.end()) throw model_error(at + "actuated names '" + a + "' twice");
        if (kin_.model()[j].free_flyer)
          throw model_error(at + "actuated: '" + a + "' is a coordinate of the floating base, which has no actuator");
        act_.push_back(j);
      }
    } else {
      for (int j = 0; j < nv_; ++j) {
        bool passive = kin_.model()[j].free_flyer;
        for (const auto& w : wheels_)
          if (w.kind == wheel_kind::castor && (w.spin == j || w.steer == j)) passive = true;
        if (!passive) act_.push_back(j);
      }
    }
    w_.assign(act_.size(), 1.0);
    for (const auto& [name, wt] : weights) {
      const int j = index_of(name, at + "weights: ");
      const auto it = std::find(act_.begin(), act_.end(), j);
      if (it == act_.end()) throw model_error(at + "weights: joint '" + name + "' is not actuated");
      if (!(wt > 0 && std::isfinite(wt))) throw model_error(at + "weights: the weight of '" + name + "' must be positive");
      w_[std::size_t(it - act_.begin())] = wt;
    }
  }
  static std::vector<std::string> pick(const std::vector<std::string>& names, const std::vector<int>& idx) {
    std::vector<std::string> out;
    for (int i : idx) out.push_back(names[std::size_t(i)]);
    return out;
  }
  static std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
    return s.empty() ? std::string("none") : s;
  }

  tree_kinematics<Sc> kin_;
  floor_plane floor_;
  int nv_, nq_;
  std::vector<std::string> names_;
  std::string name_;
  std::vector<wheel_data> wheels_;
  std::vector<row> rows_;
  std::vector<int> ind_;  ///< the independent rows (indices into rows_)
  std::vector<int> D_, I_, act_;
  std::vector<double> w_;
  std::vector<bool> on_path_;
  std::vector<std::string> dropped_;
};

}  // namespace nhdyn
