#pragma once
/// \file robot_dynamics.hpp
/// `robot_dynamics`: a loaded robot's dynamics in double behind an interface with nothing to
/// instantiate. It is the fast-to-compile front end (issue 33 item 4). The function objects
/// (rne, inverse_dynamics, …) are the library; this class calls them and adds nothing to their
/// numbers.
///
///     auto robot = nhdyn::robot_dynamics::load("my_robot.json");  // a robot file, URDF, JSON model or preset
///     Eigen::VectorXd tau = robot.inverse_dynamics(q, eta, eta_dot);  // project ∘ rne ∘ lift
///
/// Linked with `nhdyn::compiled`, this header declares the class and includes only Eigen/Core and
/// the standard library. Everything is compiled once, in the library (src/compiled/dynamics.cpp).
/// On this machine, examples/wheeled_robot.cpp compiles in seconds instead of the full headers'
/// tens of seconds (docs/performance.md, "Compile times").
///
/// Header-only (no nhdyn::compiled): this header includes the library and defines the class
/// from the same code, a template (`basic_robot_dynamics<double>`) so that its bodies are
/// compiled only in the files that use it. The same program gives the same numbers bit for bit
/// either way (tests/compiled/).
///
/// Coverage: trees with any built-in base constraint (io::robot_constraint) or none. A DH model
/// (a JSON model file, a preset) runs as its tree (io::as_robot), and the numbers differ from the
/// chain kernels' only by rounding. Scalars other than double, fixed sizes, friction, applied
/// wrenches and user constraints need the template API (nhdyn.hpp); `robot()` gives the loaded
/// robot for it. Every call checks its arguments' sizes and finiteness, and throws nhdyn::error
/// (errors.hpp) naming the argument. A nonholonomic call on a robot without a constraint throws
/// model_error; every error's message begins with the robot's name and the call. A
/// robot_dynamics is immutable: copies share one model, and concurrent calls from several
/// threads are safe. An output argument (the forms that write into storage) must not be one of
/// the same call's inputs.
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Core>

#include "config.hpp"
#include "detail/compiled_abi.hpp"
#include "errors.hpp"

namespace nhdyn {
namespace io {
struct robot_model;
}

/// ξ = (q, q̇, q̈): a joint state (the lift's output).
struct robot_state {
  Eigen::VectorXd q, qd, qdd;
};
/// τ and the constraint forces λ (inverse_dynamics_with_forces).
struct robot_forces {
  Eigen::VectorXd tau, lambda;
};
/// τ = rne(q, q̇, q̈) and its derivatives: ∂τ/∂q, ∂τ/∂q̇, ∂τ/∂q̈ = M(q).
struct rne_partials {
  Eigen::VectorXd tau;
  Eigen::MatrixXd dq, dqd, M;
};
/// q̈ of the holonomic forward dynamics and its derivatives: ∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂τ = M⁻¹.
struct forward_partials {
  Eigen::VectorXd qdd;
  Eigen::MatrixXd dq, dqd, Minv;
};
/// τ of the nonholonomic inverse dynamics and its derivatives: ∂τ/∂q, ∂τ/∂η, ∂τ/∂η̇.
struct nh_inverse_partials {
  Eigen::VectorXd tau;
  Eigen::MatrixXd dq, deta, deta_dot;
};
/// η̇ of the constrained forward dynamics and the state-space model ẋ = f(x, τ) for x = (q, η),
/// linearised: A = ∂f/∂x ((n+m) × (n+m)), B = ∂f/∂τ ((n+m) × p).
struct nh_forward_partials {
  Eigen::VectorXd eta_dot;
  Eigen::MatrixXd A, B;
};

/// The class behind `robot_dynamics` (below). It is a template only so that, header-only, its
/// bodies are compiled where a program uses them and not in every file that includes this
/// header; Scalar is double (other scalars: the template API).
template <class Scalar = double>
class basic_robot_dynamics {
  static_assert(std::is_same_v<Scalar, double>, "robot_dynamics is the double front end; other scalars: nhdyn.hpp");

 public:
  /// A vector argument: an Eigen vector of double, a segment, a map (read in place when
  /// contiguous).
  using vector_arg = const Eigen::Ref<const Eigen::VectorXd>&;

  /// The robot that `robot` names: a preset, a URDF, a robot file (a URDF with its base
  /// constraint, docs/model-format.md) or a JSON model (io::load_robot, the scenes' loader).
  static basic_robot_dynamics load(const std::string& robot);
  /// A robot already loaded (io::load_robot_file, io::as_robot, io::lock_robot).
  explicit basic_robot_dynamics(const io::robot_model& robot);
  /// Copies share the one immutable model. There is no move: a "move" copies the shared
  /// pointer, so that no robot_dynamics is ever empty.
  basic_robot_dynamics(const basic_robot_dynamics&) = default;
  basic_robot_dynamics& operator=(const basic_robot_dynamics&) = default;

  /// The loaded robot: its tree and its constraint, for the template API (io/robot_file.hpp).
  const io::robot_model& robot() const;
  const std::string& name() const;
  /// n (the size of q̇, q̈, v, and of q but for a floating base), m (of η; n without a constraint), k (constraint rows; 0
  /// without one), p (of τ for inverse_dynamics; m but for wheeled bases with other actuators).
  int dof() const;
  /// The size of q: dof() + 1 for a floating base (the root's unit quaternion,
  /// model/floating.hpp), else dof().
  int nq() const;
  bool floating() const;
  int m() const;
  int k() const;
  int p() const;
  bool constrained() const;
  /// The names of q's, η's and τ's entries.
  const std::vector<std::string>& joint_names() const;
  const std::vector<std::string>& eta_names() const;
  const std::vector<std::string>& tau_names() const;
  /// The index of a name in joint_names(), eta_names() or tau_names(); model_error naming it
  /// and the names there are when it is not one of them.
  int joint_index(const std::string& joint) const;
  int eta_index(const std::string& name) const;
  int tau_index(const std::string& name) const;

  /// The configuration space (model/floating.hpp): q ⊕ v (a floating root by SE(3)'s
  /// exponential in its own frame, the joints by +), q1 ⊖ q0, and the neutral q (zeros, the
  /// identity quaternion).
  Eigen::VectorXd integrate(vector_arg q, vector_arg v) const;
  Eigen::VectorXd difference(vector_arg q0, vector_arg q1) const;
  Eigen::VectorXd neutral_configuration() const;

  // The tree as if the base were free: the holonomic dynamics (dynamics/).
  /// v = M(q)q̈ + C(q, q̇)q̇ + g(q) (rne); the second form writes v (resized to n).
  Eigen::VectorXd rne(vector_arg q, vector_arg qd, vector_arg qdd) const;
  void rne(vector_arg q, vector_arg qd, vector_arg qdd, Eigen::VectorXd& v) const;
  /// M(q) by the composite-rigid-body algorithm; the second form writes M (resized to n × n).
  Eigen::MatrixXd mass_matrix(vector_arg q) const;
  void mass_matrix(vector_arg q, Eigen::MatrixXd& M) const;
  /// h(q, q̇) = C(q, q̇)q̇ + g(q).
  Eigen::VectorXd bias(vector_arg q, vector_arg qd) const;
  /// q̈ = M⁻¹(τ − h) (forward_dynamics: ABA or CRBA + LDLᵀ, as it chooses for the tree).
  Eigen::VectorXd forward_dynamics(vector_arg q, vector_arg qd, vector_arg tau) const;
  rne_partials rne_derivatives(vector_arg q, vector_arg qd, vector_arg qdd) const;
  forward_partials forward_dynamics_derivatives(vector_arg q, vector_arg qd, vector_arg tau) const;

  // The robot on its base constraint: the nonholonomic dynamics (constraints/, analysis/).
  /// τ = (SᵀE)⁻¹Sᵀ rne(lift(q, η, η̇)) (project ∘ rne ∘ lift); the second form writes τ
  /// (resized to p) with no allocation.
  Eigen::VectorXd inverse_dynamics(vector_arg q, vector_arg eta, vector_arg eta_dot) const;
  void inverse_dynamics(vector_arg q, vector_arg eta, vector_arg eta_dot, Eigen::VectorXd& tau) const;
  /// τ and the constraint forces λ: rne(lift(q, η, η̇)) = E(q)τ + A(q)ᵀλ.
  robot_forces inverse_dynamics_with_forces(vector_arg q, vector_arg eta, vector_arg eta_dot) const;
  /// η̇ from τ (nh_forward_dynamics).
  Eigen::VectorXd nh_forward_dynamics(vector_arg q, vector_arg eta, vector_arg tau) const;
  /// ξ = (q, S(q)η, S(q)η̇ + Ṡ(q, η)η).
  robot_state lift(vector_arg q, vector_arg eta, vector_arg eta_dot) const;
  /// q̇ = S(q)η.
  Eigen::VectorXd apply_S(vector_arg q, vector_arg eta) const;
  /// S(q) (n × m), A(q) (k × n; A S = 0), E(q) (n × p: the actuators' map, S where τ is η's).
  Eigen::MatrixXd S(vector_arg q) const;
  Eigen::MatrixXd A(vector_arg q) const;
  Eigen::MatrixXd input_map(vector_arg q) const;
  nh_inverse_partials inverse_dynamics_derivatives(vector_arg q, vector_arg eta, vector_arg eta_dot) const;
  nh_forward_partials nh_forward_dynamics_derivatives(vector_arg q, vector_arg eta, vector_arg tau) const;

 private:
  struct impl;
  std::shared_ptr<const impl> p_;
};

/// A loaded robot's dynamics in double (see the file comment).
using robot_dynamics = basic_robot_dynamics<>;
#if !NHDYN_DEFINES(NHDYN_PART_DYNAMICS)
/// Linked with nhdyn::compiled: the members are the library's (src/compiled/dynamics.cpp).
extern template class basic_robot_dynamics<double>;
#endif

}  // namespace nhdyn

#if NHDYN_DEFINES(NHDYN_PART_DYNAMICS)
#include <algorithm>
#include <optional>
#include <variant>

#include "analysis/derivatives.hpp"
#include "constraints/forward_dynamics.hpp"
#include "constraints/stages.hpp"
#include "dynamics/forward_dynamics.hpp"
#include "dynamics/rne_derivatives.hpp"
#include "dynamics/tree.hpp"
#include "io/robot_file.hpp"

namespace nhdyn {
namespace detail {
/// The nonholonomic function objects of one constraint type C on a tree.
template <class C>
struct robot_dynamics_nh {
  using tree_t = tree<double>;
  C c;
  decltype(inverse_dynamics(std::declval<const tree_t&>(), std::declval<const C&>())) id;
  decltype(inverse_dynamics_with_forces(std::declval<const tree_t&>(), std::declval<const C&>())) id_forces;
  decltype(nh_forward_dynamics(std::declval<const tree_t&>(), std::declval<const C&>())) fd;
  lift_fn<C> lifting;
  decltype(inverse_dynamics_derivatives(std::declval<const tree_t&>(), std::declval<const C&>())) id_derivatives;
  decltype(forward_dynamics_derivatives(std::declval<const tree_t&>(), std::declval<const C&>())) fd_derivatives;
  robot_dynamics_nh(const tree_t& t, const C& k)
      : c(k),
        id(inverse_dynamics(t, k)),
        id_forces(inverse_dynamics_with_forces(t, k)),
        fd(nh_forward_dynamics(t, k)),
        lifting(lift(k)),
        id_derivatives(inverse_dynamics_derivatives(t, k)),
        fd_derivatives(forward_dynamics_derivatives(t, k)) {}
};
template <class V>
struct robot_dynamics_nh_variant;
template <class... C>
struct robot_dynamics_nh_variant<std::variant<C...>> {
  using type = std::variant<robot_dynamics_nh<C>...>;
};

/// The index of `name` in `names`; model_error naming the robot, the call and the names there are.
inline int index_of(const std::vector<std::string>& names, const std::string& name, const std::string& robot,
                    const char* what) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return int(it - names.begin());
  std::string known;
  for (const auto& s : names) known += (known.empty() ? "" : ", ") + s;
  throw model_error("robot '" + robot + "', " + what + ": no entry named '" + name + "' (the names: " + known + ")");
}
}  // namespace detail

template <class Scalar>
struct basic_robot_dynamics<Scalar>::impl {
  io::robot_model robot;
  std::vector<std::string> joints, eta, tau;
  tree_rne_fn<double> rne;
  tree_mass_matrix_fn<double> M;
  tree_bias_fn<double> bias;
  decltype(nhdyn::forward_dynamics(std::declval<const tree<double>&>())) fd;
  rne_derivatives_fn<double> rne_derivatives;
  fd_derivatives_fn<double> fd_derivatives;
  std::optional<typename detail::robot_dynamics_nh_variant<io::robot_constraint>::type> nh;
  int p = 0;

  explicit impl(const io::robot_model& r)
      : robot(r),
        joints(r.model.joint_names()),
        eta(r.eta_names()),
        tau(r.tau_names()),
        rne(nhdyn::rne(r.model)),
        M(nhdyn::mass_matrix(r.model)),
        bias(nhdyn::bias(r.model)),
        fd(nhdyn::forward_dynamics(r.model)),
        rne_derivatives(nhdyn::rne_derivatives(r.model)),
        fd_derivatives(nhdyn::forward_dynamics_derivatives(r.model)),
        p(int(tau.size())) {
    if (r.constraint)
      std::visit([&](const auto& c) { nh.emplace(std::in_place_type<detail::robot_dynamics_nh<std::decay_t<decltype(c)>>>, r.model, c); },
                 *r.constraint);
  }
  /// "robot 'NAME', CALL: ", the beginning of every message of a call.
  std::string where(const char* what) const { return "robot '" + robot.name + "', " + what + ": "; }
  /// f(), its errors' messages begun by where(what) (the same exception types).
  template <class F>
  decltype(auto) guarded(const char* what, F&& f) const {
    try {
      return f();
    } catch (const input_error& e) {
      throw input_error(where(what) + e.what());
    } catch (const numerical_error& e) {
      throw numerical_error(where(what) + e.what());
    } catch (const model_error& e) {
      throw model_error(where(what) + e.what());
    }
  }
  /// f(the constraint's function objects), guarded; model_error when the robot has none.
  template <class F>
  decltype(auto) on_constraint(const char* what, F&& f) const {
    if (!nh)
      throw model_error(where(what) + "the robot has no base constraint (it was loaded without one); the holonomic "
                                      "calls (rne, mass_matrix, forward_dynamics, ...) apply");
    return guarded(what, [&]() -> decltype(auto) { return std::visit(f, *nh); });
  }
};

template <class Scalar>
basic_robot_dynamics<Scalar> basic_robot_dynamics<Scalar>::load(const std::string& robot) {
  return basic_robot_dynamics(io::load_robot(robot));
}
template <class Scalar>
basic_robot_dynamics<Scalar>::basic_robot_dynamics(const io::robot_model& robot)
    : p_(std::make_shared<const impl>(robot)) {}

template <class Scalar>
const io::robot_model& basic_robot_dynamics<Scalar>::robot() const { return p_->robot; }
template <class Scalar>
const std::string& basic_robot_dynamics<Scalar>::name() const { return p_->robot.name; }
template <class Scalar>
int basic_robot_dynamics<Scalar>::dof() const { return int(p_->joints.size()); }
template <class Scalar>
int basic_robot_dynamics<Scalar>::nq() const { return p_->robot.model.nq(); }
template <class Scalar>
bool basic_robot_dynamics<Scalar>::floating() const { return p_->robot.model.floating(); }
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::integrate(vector_arg q, vector_arg v) const {
  return p_->guarded("integrate", [&] { return Eigen::VectorXd(nhdyn::integrate(p_->robot.model, q, v)); });
}
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::difference(vector_arg q0, vector_arg q1) const {
  return p_->guarded("difference", [&] { return Eigen::VectorXd(nhdyn::difference(p_->robot.model, q0, q1)); });
}
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::neutral_configuration() const {
  return nhdyn::neutral_configuration(p_->robot.model);
}
template <class Scalar>
int basic_robot_dynamics<Scalar>::m() const { return int(p_->eta.size()); }
template <class Scalar>
int basic_robot_dynamics<Scalar>::k() const { return p_->robot.k(); }
template <class Scalar>
int basic_robot_dynamics<Scalar>::p() const { return p_->p; }
template <class Scalar>
bool basic_robot_dynamics<Scalar>::constrained() const { return p_->nh.has_value(); }
template <class Scalar>
const std::vector<std::string>& basic_robot_dynamics<Scalar>::joint_names() const { return p_->joints; }
template <class Scalar>
const std::vector<std::string>& basic_robot_dynamics<Scalar>::eta_names() const { return p_->eta; }
template <class Scalar>
const std::vector<std::string>& basic_robot_dynamics<Scalar>::tau_names() const { return p_->tau; }
template <class Scalar>
int basic_robot_dynamics<Scalar>::joint_index(const std::string& joint) const {
  return detail::index_of(p_->joints, joint, p_->robot.name, "joint_index");
}
template <class Scalar>
int basic_robot_dynamics<Scalar>::eta_index(const std::string& name) const {
  return detail::index_of(p_->eta, name, p_->robot.name, "eta_index");
}
template <class Scalar>
int basic_robot_dynamics<Scalar>::tau_index(const std::string& name) const {
  return detail::index_of(p_->tau, name, p_->robot.name, "tau_index");
}

template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::rne(vector_arg q, vector_arg qd, vector_arg qdd) const {
  return p_->guarded("rne", [&] { return Eigen::VectorXd(p_->rne(q, qd, qdd)); });
}
template <class Scalar>
void basic_robot_dynamics<Scalar>::rne(vector_arg q, vector_arg qd, vector_arg qdd, Eigen::VectorXd& v) const {
  p_->guarded("rne", [&] {
    v.resize(dof());
    p_->rne.evaluate(q, qd, qdd, v);
  });
}
template <class Scalar>
Eigen::MatrixXd basic_robot_dynamics<Scalar>::mass_matrix(vector_arg q) const {
  return p_->guarded("mass_matrix", [&] { return Eigen::MatrixXd(p_->M(q)); });
}
template <class Scalar>
void basic_robot_dynamics<Scalar>::mass_matrix(vector_arg q, Eigen::MatrixXd& M) const {
  p_->guarded("mass_matrix", [&] { p_->M.evaluate(q, M); });
}
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::bias(vector_arg q, vector_arg qd) const {
  return p_->guarded("bias", [&] { return Eigen::VectorXd(p_->bias(q, qd)); });
}
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::forward_dynamics(vector_arg q, vector_arg qd, vector_arg tau) const {
  return p_->guarded("forward_dynamics", [&] { return Eigen::VectorXd(p_->fd(q, qd, tau)); });
}
template <class Scalar>
rne_partials basic_robot_dynamics<Scalar>::rne_derivatives(vector_arg q, vector_arg qd, vector_arg qdd) const {
  return p_->guarded("rne_derivatives", [&] {
    auto r = p_->rne_derivatives(q, qd, qdd);
    return rne_partials{std::move(r.tau), std::move(r.dq), std::move(r.dqd), std::move(r.M)};
  });
}
template <class Scalar>
forward_partials basic_robot_dynamics<Scalar>::forward_dynamics_derivatives(vector_arg q, vector_arg qd,
                                                                            vector_arg tau) const {
  return p_->guarded("forward_dynamics_derivatives", [&] {
    auto r = p_->fd_derivatives(q, qd, tau);
    return forward_partials{std::move(r.qdd), std::move(r.dq), std::move(r.dqd), std::move(r.Minv)};
  });
}

template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::inverse_dynamics(vector_arg q, vector_arg eta, vector_arg eta_dot) const {
  return p_->on_constraint("inverse_dynamics", [&](const auto& x) -> Eigen::VectorXd { return x.id(q, eta, eta_dot); });
}
template <class Scalar>
void basic_robot_dynamics<Scalar>::inverse_dynamics(vector_arg q, vector_arg eta, vector_arg eta_dot,
                                                    Eigen::VectorXd& tau) const {
  p_->on_constraint("inverse_dynamics", [&](const auto& x) {
    tau.resize(p());
    if constexpr (requires { x.id.evaluate(q, eta, eta_dot, tau); })
      x.id.evaluate(q, eta, eta_dot, tau);
    else
      tau = x.id(q, eta, eta_dot);
  });
}
template <class Scalar>
robot_forces basic_robot_dynamics<Scalar>::inverse_dynamics_with_forces(vector_arg q, vector_arg eta,
                                                                        vector_arg eta_dot) const {
  return p_->on_constraint("inverse_dynamics_with_forces", [&](const auto& x) {
    auto f = x.id_forces(q, eta, eta_dot);
    return robot_forces{std::move(f.tau), std::move(f.lambda)};
  });
}
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::nh_forward_dynamics(vector_arg q, vector_arg eta, vector_arg tau) const {
  return p_->on_constraint("nh_forward_dynamics", [&](const auto& x) -> Eigen::VectorXd { return x.fd(q, eta, tau); });
}
template <class Scalar>
robot_state basic_robot_dynamics<Scalar>::lift(vector_arg q, vector_arg eta, vector_arg eta_dot) const {
  return p_->on_constraint("lift", [&](const auto& x) {
    auto xi = x.lifting(q, eta, eta_dot);
    return robot_state{std::move(xi.q), std::move(xi.qd), std::move(xi.qdd)};
  });
}
template <class Scalar>
Eigen::VectorXd basic_robot_dynamics<Scalar>::apply_S(vector_arg q, vector_arg eta) const {
  return p_->on_constraint("apply_S", [&](const auto& x) -> Eigen::VectorXd {
    detail::check_size(q, x.c.dof(), "q");
    detail::check_size(eta, x.c.m(), "eta");
    detail::check_finite(q, "q");
    detail::check_finite(eta, "eta");
    return nhdyn::apply_S(x.c, q, eta);
  });
}
template <class Scalar>
Eigen::MatrixXd basic_robot_dynamics<Scalar>::S(vector_arg q) const {
  return p_->on_constraint("S", [&](const auto& x) -> Eigen::MatrixXd {
    detail::check_size(q, x.c.dof(), "q");
    detail::check_finite(q, "q");
    return x.c.S(q);
  });
}
template <class Scalar>
Eigen::MatrixXd basic_robot_dynamics<Scalar>::A(vector_arg q) const {
  return p_->on_constraint("A", [&](const auto& x) -> Eigen::MatrixXd {
    detail::check_size(q, x.c.dof(), "q");
    detail::check_finite(q, "q");
    return x.c.A(q);
  });
}
template <class Scalar>
Eigen::MatrixXd basic_robot_dynamics<Scalar>::input_map(vector_arg q) const {
  return p_->on_constraint("input_map", [&](const auto& x) -> Eigen::MatrixXd {
    detail::check_size(q, x.c.dof(), "q");
    detail::check_finite(q, "q");
    return nhdyn::input_map(x.c, q);
  });
}
template <class Scalar>
nh_inverse_partials basic_robot_dynamics<Scalar>::inverse_dynamics_derivatives(vector_arg q, vector_arg eta,
                                                                               vector_arg eta_dot) const {
  return p_->on_constraint("inverse_dynamics_derivatives", [&](const auto& x) {
    auto r = x.id_derivatives(q, eta, eta_dot);
    return nh_inverse_partials{std::move(r.tau), std::move(r.dq), std::move(r.deta), std::move(r.deta_dot)};
  });
}
template <class Scalar>
nh_forward_partials basic_robot_dynamics<Scalar>::nh_forward_dynamics_derivatives(vector_arg q, vector_arg eta,
                                                                                  vector_arg tau) const {
  return p_->on_constraint("nh_forward_dynamics_derivatives", [&](const auto& x) {
    auto r = x.fd_derivatives(q, eta, tau);
    return nh_forward_partials{std::move(r.eta_dot), std::move(r.ss.A), std::move(r.ss.B)};
  });
}

}  // namespace nhdyn
#endif
