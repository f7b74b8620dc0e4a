/// \file python/nhdyn_module.cpp
/// The Python module `nhdyn` (pybind11): the library's models and dynamics on NumPy arrays,
/// functional as in C++ — `nhdyn.rne(model)` returns a callable — and batched: every callable
/// takes one state (1-D arrays) or many (2-D arrays, one state per row), the rows computed in
/// C++ with the GIL released, optionally on several threads. docs/python.md is the guide.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <span>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <nhdyn/analysis/bounds.hpp>
#include <nhdyn/analysis/linearize.hpp>
#include <nhdyn/dynamics/terms.hpp>
#include <nhdyn/io/json.hpp>
#include <nhdyn/simulation/batch.hpp>
#include <nhdyn/simulation/scene.hpp>
#include <nhdyn/nhdyn.hpp>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>
#if NHDYN_PY_URDF
#include <nhdyn/io/robot_file.hpp>
#include <nhdyn/io/urdf.hpp>
#include <nhdyn/simulation/robot_scene.hpp>
#endif

namespace py = pybind11;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

/// A loaded model: a DH chain (with a differential drive or not) or a tree (with any base
/// constraint or not).
struct model {
  std::string name, source;
  std::optional<nhdyn::chain<double>> chain;
  std::optional<nhdyn::differential_drive<double>> chain_constraint;
  std::optional<nhdyn::tree<double>> tree;
  std::optional<nhdyn::base_constraint> tree_constraint;
  std::vector<std::string> joints, eta, tau;
  std::vector<std::pair<std::string, double>> locked;  ///< joints held (load's locked=), full q order
  std::vector<std::pair<std::string, double>> requested;  ///< load's locked= as given (the file's own "locked" not included)
  int dof() const { return int(joints.size()); }
  int m() const { return int(eta.size()); }
  bool constrained() const { return chain_constraint || tree_constraint; }

  /// constrained(model, c) or holonomic(model), as the tool's dispatch.
  template <class Constrained, class Holonomic>
  auto dispatch(const Constrained& constrained_fn, const Holonomic& holonomic_fn) const {
    if (tree) {
      if (tree_constraint)
        return std::visit([&](const auto& c) { return constrained_fn(*tree, c); }, *tree_constraint);
      return holonomic_fn(*tree);
    }
    if (chain_constraint) return constrained_fn(*chain, *chain_constraint);
    return holonomic_fn(*chain);
  }
};

bool ends_with_urdf(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s.size() > 5 && s.compare(s.size() - 5, 5, ".urdf") == 0;
}
bool is_robot_file(const std::string& spec) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(spec, ec)) return false;
  std::ifstream in(spec);
  const auto j = nlohmann::json::parse(in, nullptr, false);
  return j.is_object() && j.contains("urdf");
}

#if NHDYN_PY_URDF
/// A robot (a robot file's, or a DH model's with joints held) as the module's model.
void take_robot(model& out, nhdyn::io::robot_model r) {
  out.name = r.name;
  out.eta = r.eta_names();
  out.tau = r.tau_names();
  out.locked = r.locked;
  out.tree = std::move(r.model);
  out.tree_constraint = r.constraint;
}
#endif

std::shared_ptr<model> load(const std::string& spec, bool strict, const std::map<std::string, double>& locked) {
  auto out = std::make_shared<model>();
  out->source = spec;
  out->requested.assign(locked.begin(), locked.end());
  const bool urdf = ends_with_urdf(spec), robot = !urdf && is_robot_file(spec);
  const std::vector<std::pair<std::string, double>> locks(locked.begin(), locked.end());
  if (urdf || robot) {
#if NHDYN_PY_URDF
    nhdyn::io::urdf_options o;
    o.strict = strict;
    if (robot) {
      take_robot(*out, nhdyn::io::lock_robot(nhdyn::io::load_robot_file(spec, o), locks, "locked: "));
    } else {
      // a URDF is a robot without a constraint: lock_robot locks its tree and names what it held
      auto r = nhdyn::io::lock_robot({nhdyn::io::load_urdf(spec, o), std::nullopt, ""}, locks, "locked: ");
      out->locked = std::move(r.locked);
      out->tree = std::move(r.model);
      out->name = out->tree->name();
    }
    out->joints = out->tree->joint_names();
    if (!robot) out->eta = out->tau = out->joints;
    return out;
#else
    throw nhdyn::model_error(spec + ": this nhdyn module was built without URDF support (liburdfdom-dev, libtinyxml2-dev)");
#endif
  }
  (void)strict;
  auto m = nhdyn::io::load<double>(spec);
  if (!locks.empty() || !m.locked.empty()) {
#if NHDYN_PY_URDF
    // a DH chain with joints held is a tree (io::as_robot): the file's "locked", then locked=
    take_robot(*out, nhdyn::io::lock_robot(nhdyn::io::as_robot(m, "model '" + spec + "', locked: "), locks, "locked: "));
    out->joints = out->tree->joint_names();
    return out;
#else
    throw nhdyn::model_error("'" + spec + "': locking joints of a DH model makes a tree, and this nhdyn module was built "
                             "without tree support (liburdfdom-dev, libtinyxml2-dev)");
#endif
  }
  out->name = m.chain.name();
  for (int i = 0; i < m.chain.dof(); ++i) out->joints.push_back("joint" + std::to_string(i + 1));
  out->eta = m.constraint ? m.constraint->eta_names(out->joints) : out->joints;
  out->tau = out->eta;
  out->chain = std::move(m.chain);
  out->chain_constraint = m.constraint;
  return out;
}

// ---------------------------------------------------------------------------------------
// Batched callables
// ---------------------------------------------------------------------------------------

/// One output array of a callable: a vector of `rows` entries, or a rows × cols matrix.
struct output {
  std::string name;
  int rows = 0, cols = 0;  // cols 0: a vector
  int size() const { return cols ? rows * cols : rows; }
};

/// A function of k vectors (sizes `args`) with outputs `outs`, callable on one state or a
/// batch. `f(in, out)`: in[j] points at argument j's entries, out[o] at output o's storage
/// (row-major for a matrix).
class batch_function {
 public:
  using kernel = std::function<void(std::span<const double* const>, std::span<double* const>)>;
  batch_function(std::string name, std::vector<std::pair<std::string, int>> args, std::vector<output> outs, kernel f)
      : name_(std::move(name)), args_(std::move(args)), outs_(std::move(outs)), f_(std::move(f)) {}

  py::object call(const py::args& a, int threads) const {
    if (auto fast = call_one(a, threads)) return std::move(*fast);
    if (a.size() != args_.size()) {
      std::string want;
      for (const auto& x : args_) want += (want.empty() ? "" : ", ") + x.first;
      throw py::type_error(name_ + "(" + want + "): takes " + std::to_string(args_.size()) + " arrays, got " +
                           std::to_string(a.size()));
    }
    std::vector<py::array_t<double, py::array::c_style>> in;
    py::ssize_t batch = -1;  // -1: one state (1-D arrays)
    for (std::size_t j = 0; j < args_.size(); ++j) {
      const auto& [arg, n] = args_[j];
      py::array raw = py::array::ensure(a[j]);
      if (!raw) throw py::type_error(name_ + ": '" + arg + "' is not an array of numbers");
      const char kind = raw.dtype().kind();
      if (kind != 'f' && kind != 'i' && kind != 'u')
        throw py::type_error(name_ + ": '" + arg + "' has dtype " + std::string(py::str(raw.dtype())) +
                             "; real numbers (float or int arrays, converted to float64) only");
      auto x = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(raw);
      if (x && !(py::detail::array_proxy(x.ptr())->flags & py::detail::npy_api::NPY_ARRAY_ALIGNED_))
        x = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(x.attr("copy")());  // aligned
      if (x.ndim() != 1 && x.ndim() != 2)
        throw nhdyn::input_error(name_ + ": '" + arg + "' must be 1-D (one state) or 2-D (one state per row), not " +
                              std::to_string(x.ndim()) + "-D");
      const py::ssize_t len = x.shape(x.ndim() - 1), rows = x.ndim() == 2 ? x.shape(0) : -1;
      if (len != n)
        throw nhdyn::input_error(name_ + ": '" + arg + "' has " + std::to_string(len) + " entries; the model needs " +
                              std::to_string(n));
      if (j == 0) batch = rows;
      else if (rows != batch)
        throw nhdyn::input_error(name_ + ": '" + arg + "' is " + (rows < 0 ? "1-D" : std::to_string(rows) + " rows") + " but '" +
                              args_[0].first + "' is " + (batch < 0 ? "1-D" : std::to_string(batch) + " rows"));
      in.push_back(std::move(x));
    }
    const py::ssize_t count = batch < 0 ? 1 : batch;
    std::vector<py::array_t<double>> out;
    for (const auto& o : outs_) {
      std::vector<py::ssize_t> shape;
      if (batch >= 0) shape.push_back(batch);
      shape.push_back(o.rows);
      if (o.cols) shape.push_back(o.cols);
      out.emplace_back(shape);
    }
    std::vector<const double*> ip;
    for (const auto& x : in) ip.push_back(x.data());
    std::vector<double*> op;
    for (auto& x : out) op.push_back(x.mutable_data());
    run(ip, op, count, threads);
    if (out.size() == 1) return std::move(out[0]);
    py::tuple t(out.size());
    for (std::size_t o = 0; o < out.size(); ++o) t[o] = std::move(out[o]);
    return t;
  }

  std::string signature() const {
    std::string s = name_ + "(";
    for (std::size_t j = 0; j < args_.size(); ++j)
      s += (j ? ", " : "") + args_[j].first + "[" + std::to_string(args_[j].second) + "]";
    s += ") -> ";
    for (std::size_t o = 0; o < outs_.size(); ++o)
      s += (o ? ", " : "") + outs_[o].name + "[" + std::to_string(outs_[o].rows) + (outs_[o].cols ? "x" + std::to_string(outs_[o].cols) : "") + "]";
    return s;
  }

 private:
  /// The common case at the least cost: one state of float64, C-contiguous 1-D arrays of the
  /// right sizes — no conversions, no heap bookkeeping beyond the result arrays (the
  /// single-call overhead, docs/python.md). Anything else (batches, other dtypes, wrong
  /// sizes and their messages): empty, and `call` takes the general path.
  std::optional<py::object> call_one(const py::args& a, int threads) const {
    constexpr std::size_t max_args = 8, max_outs = 4;
    const std::size_t k = a.size();
    if (threads > 1 || k != args_.size() || k > max_args || outs_.size() > max_outs) return std::nullopt;
    std::array<const double*, max_args> ip{};
    for (std::size_t j = 0; j < k; ++j) {
      const py::handle h = PyTuple_GET_ITEM(a.ptr(), py::ssize_t(j));  // borrowed: the tuple keeps it alive
      if (!py::array_t<double, py::array::c_style>::check_(h)) return std::nullopt;  // native float64, C order
      const auto* p = py::detail::array_proxy(h.ptr());
      if (p->nd != 1 || p->dimensions[0] != args_[j].second || !(p->flags & py::detail::npy_api::NPY_ARRAY_ALIGNED_))
        return std::nullopt;
      ip[j] = reinterpret_cast<const double*>(p->data);
    }
    std::array<py::object, max_outs> out;
    std::array<double*, max_outs> op{};
    for (std::size_t o = 0; o < outs_.size(); ++o) {
      py::array_t<double> x = outs_[o].cols ? py::array_t<double>({py::ssize_t(outs_[o].rows), py::ssize_t(outs_[o].cols)})
                                            : py::array_t<double>(py::ssize_t(outs_[o].rows));
      op[o] = x.mutable_data();
      out[o] = std::move(x);
    }
    f_(std::span<const double* const>(ip.data(), k), std::span<double* const>(op.data(), outs_.size()));
    ++fast_calls;
    if (outs_.size() == 1) return std::move(out[0]);
    py::tuple t(outs_.size());
    for (std::size_t o = 0; o < outs_.size(); ++o) t[o] = std::move(out[o]);
    return py::object(std::move(t));
  }

  /// Rows [0, count): with the GIL released, on `threads` threads (≤ 1: this one). The first
  /// error (by row) is rethrown, naming the row for a batch.
  void run(std::span<const double* const> in, std::span<double* const> out, py::ssize_t count, int threads) const {
    const bool batch = count > 1 || threads > 1;
    if (!batch) {  // one state: no GIL hand-over, no bookkeeping (the call's overhead, docs/python.md)
      f_(in, out);
      return;
    }
    std::vector<std::exception_ptr> errors(std::size_t(std::max(1, threads)));
    std::vector<py::ssize_t> error_row(errors.size(), -1);
    const auto rows = [&](int worker, py::ssize_t begin, py::ssize_t end) {
      std::vector<const double*> ip(in.size());
      std::vector<double*> op(out.size());
      for (py::ssize_t r = begin; r < end; ++r) {
        for (std::size_t j = 0; j < in.size(); ++j) ip[j] = in[j] + r * args_[j].second;
        for (std::size_t o = 0; o < out.size(); ++o) op[o] = out[o] + r * outs_[o].size();
        try {
          f_(ip, op);
        } catch (...) {
          errors[std::size_t(worker)] = std::current_exception();
          error_row[std::size_t(worker)] = r;
          return;
        }
      }
    };
    {
      py::gil_scoped_release release;
      const int t = int(std::min<py::ssize_t>(std::max(1, threads), count));
      if (t <= 1) {
        rows(0, 0, count);
      } else {
        std::vector<std::thread> pool;
        for (int w = 0; w < t; ++w) pool.emplace_back(rows, w, count * w / t, count * (w + 1) / t);
        for (auto& th : pool) th.join();
      }
    }
    for (std::size_t w = 0; w < errors.size(); ++w)
      if (errors[w]) {
        if (!batch) std::rethrow_exception(errors[w]);
        try {
          std::rethrow_exception(errors[w]);
        } catch (const nhdyn::model_error& e) {
          throw nhdyn::model_error("row " + std::to_string(error_row[w]) + ": " + e.what());
        } catch (const nhdyn::input_error& e) {
          throw nhdyn::input_error("row " + std::to_string(error_row[w]) + ": " + e.what());
        } catch (const nhdyn::numerical_error& e) {
          throw nhdyn::numerical_error("row " + std::to_string(error_row[w]) + ": " + e.what());
        }
      }
  }

  std::string name_;
  std::vector<std::pair<std::string, int>> args_;
  std::vector<output> outs_;
  kernel f_;

 public:
  /// Calls that took call_one's path (nhdyn._fast_path_calls(): tests check which path ran).
  static inline std::atomic<long long> fast_calls{0};
};

using rowmajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using cmap = Eigen::Map<const VectorXd>;
using vmap = Eigen::Map<VectorXd>;

template <class Model>
batch_function rne_of(const Model& mdl) {
  const int n = mdl.dof();
  const auto f = nhdyn::rne(mdl);
  return {"rne", {{"q", n}, {"qd", n}, {"qdd", n}}, {{"tau", n}}, [f, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(cmap(in[0], n), cmap(in[1], n), cmap(in[2], n));
          }};
}
template <class Model>
batch_function mass_matrix_of(const Model& mdl) {
  const int n = mdl.dof();
  const auto f = nhdyn::mass_matrix(mdl);
  return {"mass_matrix", {{"q", n}}, {{"M", n, n}}, [f, n](const auto& in, const auto& out) {
            Eigen::Map<rowmajor>(out[0], n, n) = f(cmap(in[0], n));
          }};
}
template <class Model>
batch_function bias_of(const Model& mdl) {
  const int n = mdl.dof();
  const auto f = nhdyn::bias(mdl);
  return {"bias", {{"q", n}, {"qd", n}}, {{"h", n}}, [f, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(cmap(in[0], n), cmap(in[1], n));
          }};
}
template <class Model>
batch_function holonomic_fd_of(const Model& mdl) {
  const int n = mdl.dof();
  const auto f = nhdyn::forward_dynamics(mdl);
  return {"forward_dynamics", {{"q", n}, {"qd", n}, {"tau", n}}, {{"qdd", n}}, [f, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(cmap(in[0], n), cmap(in[1], n), cmap(in[2], n));
          }};
}
template <class Model, class C>
batch_function nh_id_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), k = c.m(), p = nhdyn::actuator_count(c);
  const auto f = nhdyn::inverse_dynamics(mdl, c);
  return {"inverse_dynamics", {{"q", n}, {"eta", k}, {"eta_dot", k}}, {{"tau", p}}, [f, n, k, p](const auto& in, const auto& out) {
            // the state in per-thread vectors of the library's own type (the call's evaluate
            // path, stack scratch and τ its one allocation, takes Maps as well since 2026-12-02)
            thread_local VectorXd q, eta, eta_dot;
            q = cmap(in[0], n), eta = cmap(in[1], k), eta_dot = cmap(in[2], k);
            vmap(out[0], p) = f(q, eta, eta_dot);
          }};
}
template <class Model, class C>
batch_function nh_id_forces_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), m = c.m(), k = c.k(), p = nhdyn::actuator_count(c);
  const auto f = nhdyn::inverse_dynamics_with_forces(mdl, c);
  return {"inverse_dynamics_with_forces", {{"q", n}, {"eta", m}, {"eta_dot", m}}, {{"tau", p}, {"lambda", k}},
          [f, n, m, k, p](const auto& in, const auto& out) {
            const auto r = f(cmap(in[0], n), cmap(in[1], m), cmap(in[2], m));
            vmap(out[0], p) = r.tau;
            vmap(out[1], k) = r.lambda;
          }};
}
template <class Model, class C>
batch_function nh_fd_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  const auto f = nhdyn::nh_forward_dynamics(mdl, c);
  return {"forward_dynamics", {{"q", n}, {"eta", m}, {"tau", p}}, {{"eta_dot", m}}, [f, n, m, p](const auto& in, const auto& out) {
            vmap(out[0], m) = f(cmap(in[0], n), cmap(in[1], m), cmap(in[2], p));
          }};
}


// ---------------------------------------------------------------------------------------
// Drives and contacts: friction stages and external wrenches (docs/api.md §3a)
// ---------------------------------------------------------------------------------------

/// Wrenches from Python: a list of dicts {"body": name, "frame": "world" | "body", "point",
/// "force", "moment"} (3 numbers each; zeros by default), as the tool's "f_ext".
template <class Model>
std::vector<nhdyn::wrench<double>> wrenches_from(const Model& mdl, const py::list& list) {
  std::vector<nhdyn::wrench<double>> out;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const std::string w = "wrenches[" + std::to_string(k) + "]";
    if (!py::isinstance<py::dict>(list[k])) throw nhdyn::input_error(w + ": a dict {\"body\", \"force\", ...}");
    const auto d = list[k].cast<py::dict>();
    for (const auto& [key, value] : d) {
      const std::string k2 = py::str(key);
      if (k2 != "body" && k2 != "frame" && k2 != "point" && k2 != "force" && k2 != "moment")
        throw nhdyn::input_error(w + ": unknown key '" + k2 + "' (known: body, frame, point, force, moment)");
    }
    if (!d.contains("body")) throw nhdyn::input_error(w + ": 'body' (a body name) is missing");
    if (!py::isinstance<py::str>(d["body"])) throw nhdyn::input_error(w + ": 'body' must be a body's name (a string)");
    nhdyn::wrench_frame frame = nhdyn::wrench_frame::world;
    if (d.contains("frame")) {
      const std::string f = py::str(d["frame"]);
      if (f == "body") frame = nhdyn::wrench_frame::body;
      else if (f != "world") throw nhdyn::input_error(w + ": 'frame' must be \"world\" or \"body\"");
    }
    const auto v3 = [&](const char* key) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      if (!d.contains(key)) return v;
      const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(d[key]);
      if (!a || a.ndim() != 1 || a.shape(0) != 3) throw nhdyn::input_error(w + "." + key + ": 3 numbers");
      for (int r = 0; r < 3; ++r) {
        v(r) = a.at(r);
        if (!std::isfinite(v(r))) throw nhdyn::input_error(w + "." + key + ": not finite");
      }
      return v;
    };
    out.push_back(nhdyn::wrench_on(mdl, d["body"].cast<std::string>(), frame, v3("point"), v3("force"), v3("moment")));
  }
  return out;
}

template <class Model>
batch_function rne_wrenches_of(const Model& mdl, const py::list& w) {
  const int n = mdl.dof();
  const auto f = nhdyn::rne(mdl);
  const auto fx = nhdyn::external_wrenches(mdl, wrenches_from(mdl, w));
  return {"rne", {{"q", n}, {"qd", n}, {"qdd", n}}, {{"tau", n}}, [f, fx, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], n)), VectorXd(cmap(in[2], n)), fx);
          }};
}
template <class Model, class C>
batch_function nh_id_wrenches_of(const Model& mdl, const C& c, const py::list& w) {
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  const auto fx = nhdyn::external_wrenches(mdl, wrenches_from(mdl, w));
  const auto f = nhdyn::lift(c) | nhdyn::rne(mdl) | fx | nhdyn::constraint_forces(c);
  return {"inverse_dynamics", {{"q", n}, {"eta", m}, {"eta_dot", m}}, {{"tau", p}}, [f, n, m, p](const auto& in, const auto& out) {
            vmap(out[0], p) = f(nhdyn::reduced_state<double>{VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], m)),
                                                             VectorXd(cmap(in[2], m))}).tau;
          }};
}
/// Python's terms= (a comma-separated string, or a list of names) and smooth= as nhdyn::terms.
nhdyn::terms terms_from(const py::object& t, double smooth) {
  std::string list;
  if (py::isinstance<py::str>(t)) {
    list = t.cast<std::string>();
  } else {
    for (const auto& x : t) list += (list.empty() ? "" : ",") + py::str(x).cast<std::string>();
    if (list.empty()) list = "none";
  }
  auto r = nhdyn::terms::parse(list);
  if (smooth != 0) {
    if (!r.friction) throw nhdyn::input_error("smooth: the terms do not include friction");
    r.coulomb = nhdyn::coulomb_law::smooth(smooth);
  }
  return r;
}
/// The friction the terms include: the model's, or none (zero laws, which add exactly 0).
template <class Model>
nhdyn::friction_fn terms_friction(const Model& mdl, const nhdyn::terms& t) {
  return t.friction ? nhdyn::friction(mdl, t.coulomb)
                    : nhdyn::friction_fn(std::vector<nhdyn::joint_friction>(static_cast<std::size_t>(mdl.dof())));
}
/// rne with the terms chosen (and the wrenches, if any): rne(model, t.rne()) + friction.
template <class Model>
batch_function rne_terms_of(const Model& full, const nhdyn::terms& t, const std::optional<py::list>& w) {
  const Model mdl = nhdyn::with_terms(full, t);
  const int n = mdl.dof();
  const auto f = nhdyn::rne(mdl, t.rne()) + terms_friction(mdl, t);
  const auto fx = nhdyn::external_wrenches(mdl, w ? wrenches_from(mdl, *w) : std::vector<nhdyn::wrench<double>>{});
  return {"rne", {{"q", n}, {"qd", n}, {"qdd", n}}, {{"tau", n}}, [f, fx, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], n)), VectorXd(cmap(in[2], n)), fx);
          }};
}
/// The nonholonomic inverse dynamics with the terms chosen: lift | rne + friction | wrenches | project.
template <class Model, class C>
batch_function nh_id_terms_of(const Model& full, const C& c, const nhdyn::terms& t, const std::optional<py::list>& w) {
  const Model mdl = nhdyn::with_terms(full, t);
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  const auto fx = nhdyn::external_wrenches(mdl, w ? wrenches_from(mdl, *w) : std::vector<nhdyn::wrench<double>>{});
  const auto f = nhdyn::lift(c) | (nhdyn::rne(mdl, t.rne()) + terms_friction(mdl, t)) | fx | nhdyn::constraint_forces(c);
  return {"inverse_dynamics", {{"q", n}, {"eta", m}, {"eta_dot", m}}, {{"tau", p}}, [f, n, m, p](const auto& in, const auto& out) {
            vmap(out[0], p) = f(nhdyn::reduced_state<double>{VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], m)),
                                                             VectorXd(cmap(in[2], m))}).tau;
          }};
}
template <class Model>
batch_function holonomic_fd_wrenches_of(const Model& mdl, const py::list& w) {
  const int n = mdl.dof();
  const auto f = nhdyn::forward_dynamics(mdl);
  const auto fx = nhdyn::external_wrenches(mdl, wrenches_from(mdl, w));
  return {"forward_dynamics", {{"q", n}, {"qd", n}, {"tau", n}}, {{"qdd", n}}, [f, fx, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], n)), VectorXd(cmap(in[2], n)), fx);
          }};
}
template <class Model, class C>
batch_function nh_fd_wrenches_of(const Model& mdl, const C& c, const py::list& w) {
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  const auto f = nhdyn::nh_forward_dynamics(mdl, c);
  const auto fx = nhdyn::external_wrenches(mdl, wrenches_from(mdl, w));
  return {"forward_dynamics", {{"q", n}, {"eta", m}, {"tau", p}}, {{"eta_dot", m}}, [f, fx, n, m, p](const auto& in, const auto& out) {
            vmap(out[0], m) = f(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], m)), VectorXd(cmap(in[2], p)), fx);
          }};
}
template <class Model>
batch_function generalized_force_of(const Model& mdl, const py::list& w) {
  const int n = mdl.dof();
  const auto fx = nhdyn::external_wrenches(mdl, wrenches_from(mdl, w));
  return {"generalized_force", {{"q", n}}, {{"Q", n}}, [fx, n](const auto& in, const auto& out) {
            const VectorXd q = cmap(in[0], n);
            if (!q.allFinite()) throw nhdyn::input_error("generalized_force: q is not finite");
            vmap(out[0], n) = fx.generalized_force(q);
          }};
}
template <class Model>
batch_function friction_of(const Model& mdl, double smooth) {
  const int n = mdl.dof();
  if (!(smooth >= 0) || !std::isfinite(smooth)) throw nhdyn::input_error("friction: smooth must be a finite v_s ≥ 0 [rad/s or m/s]");
  const auto f = smooth > 0 ? nhdyn::friction(mdl, nhdyn::coulomb_law::smooth(smooth)) : nhdyn::friction(mdl);
  return {"friction", {{"qd", n}}, {{"tau_f", n}}, [f, n](const auto& in, const auto& out) {
            vmap(out[0], n) = f(VectorXd(cmap(in[0], n)));
          }};
}

template <class Model, class C>
batch_function lift_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), m = c.m();
  const auto f = nhdyn::lift(c);
  return {"lift", {{"q", n}, {"eta", m}, {"eta_dot", m}}, {{"q", n}, {"qd", n}, {"qdd", n}}, [f, n, m](const auto& in, const auto& out) {
            const auto xi = f(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], m)), VectorXd(cmap(in[2], m)));
            vmap(out[0], n) = xi.q;
            vmap(out[1], n) = xi.qd;
            vmap(out[2], n) = xi.qdd;
          }};
}
template <class Model, class C>
batch_function project_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), p = nhdyn::actuator_count(c);
  const auto f = nhdyn::project(c);
  return {"project", {{"q", n}, {"v", n}}, {{"tau", p}}, [f, n, p](const auto& in, const auto& out) {
            vmap(out[0], p) = f(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], n)));
          }};
}

nhdyn::kinematics<double> kinematics_of(const nhdyn::chain<double>& c) { return nhdyn::kinematics<double>(c); }
nhdyn::tree_kinematics<double> kinematics_of(const nhdyn::tree<double>& t) { return nhdyn::tree_kinematics<double>(t); }

template <class Model>
batch_function frame_of(const Model& mdl, const std::string& name) {
  const int n = mdl.dof();
  const auto s = nhdyn::find_frame(mdl, name);  // s.body: 0-based, −1 the base
  const auto kin = kinematics_of(mdl);
  return {"frame", {{"q", n}}, {{"T", 4, 4}}, [kin, s](const auto& in, const auto& out) {
            const auto X = kin.frame(cmap(in[0], kin.dof()), s.body + 1);
            Eigen::Map<Eigen::Matrix<double, 4, 4, Eigen::RowMajor>> T(out[0]);
            T.setIdentity();
            T.template topLeftCorner<3, 3>() = X.R * s.R;
            T.template topRightCorner<3, 1>() = X.p + X.R * s.p;
          }};
}
template <class Model>
batch_function jacobian_of(const Model& mdl, const std::string& name, const Eigen::Vector3d& point) {
  const int n = mdl.dof();
  const auto s = nhdyn::find_frame(mdl, name);
  const Eigen::Vector3d p = s.R * point + s.p;
  const auto kin = kinematics_of(mdl);
  const int body = s.body + 1;
  return {"jacobian", {{"q", n}}, {{"J", 6, n}}, [kin, body, p, n](const auto& in, const auto& out) {
            Eigen::Map<rowmajor>(out[0], 6, n) = kin.jacobian(cmap(in[0], n), body, p);
          }};
}

template <class Model>
batch_function holonomic_linearize_of(const Model& mdl) {
  const int n = mdl.dof();
  return {"linearize", {{"q", n}, {"qd", n}, {"tau", n}}, {{"A", 2 * n, 2 * n}, {"B", 2 * n, n}}, [mdl, n](const auto& in, const auto& out) {
            const auto ss = nhdyn::linearize_forward_dynamics(mdl, cmap(in[0], n), cmap(in[1], n), cmap(in[2], n));
            Eigen::Map<rowmajor>(out[0], 2 * n, 2 * n) = ss.A;
            Eigen::Map<rowmajor>(out[1], 2 * n, n) = ss.B;
          }};
}
template <class Model, class C>
batch_function nh_linearize_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  return {"linearize", {{"q", n}, {"eta", m}, {"tau", p}}, {{"A", n + m, n + m}, {"B", n + m, p}}, [mdl, c, n, m, p](const auto& in, const auto& out) {
            const auto ss = nhdyn::linearize_forward_dynamics(mdl, c, cmap(in[0], n), cmap(in[1], m), cmap(in[2], p));
            Eigen::Map<rowmajor>(out[0], n + m, n + m) = ss.A;
            Eigen::Map<rowmajor>(out[1], n + m, p) = ss.B;
          }};
}

template <class Model, class C>
batch_function nh_state_derivative_of(const Model& mdl, const C& c) {
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  const auto f = nhdyn::nh_forward_dynamics(mdl, c);
  return {"state_derivative", {{"q", n}, {"eta", m}, {"tau", p}}, {{"xdot", n + m}}, [f, n, m, p](const auto& in, const auto& out) {
            vmap(out[0], n + m) = f.state_derivative(VectorXd(cmap(in[0], n)), VectorXd(cmap(in[1], m)), VectorXd(cmap(in[2], p)));
          }};
}
template <class Model>
batch_function holonomic_state_derivative_of(const Model& mdl) {
  const int n = mdl.dof();
  const auto f = nhdyn::forward_dynamics(mdl);
  return {"state_derivative", {{"q", n}, {"qd", n}, {"tau", n}}, {{"xdot", 2 * n}}, [f, n](const auto& in, const auto& out) {
            vmap(out[0], n) = cmap(in[1], n);
            vmap(out[0] + n, n) = f(cmap(in[0], n), cmap(in[1], n), cmap(in[2], n));
          }};
}

/// Interval boxes from (lo, hi) arrays.
nhdyn::box<nhdyn::dynamic> box_of(const double* lo, const double* hi, int n) {
  nhdyn::box<nhdyn::dynamic> b(n);
  for (int i = 0; i < n; ++i) b(i) = nhdyn::interval(lo[i], hi[i]);  // checked by torque_bounds
  return b;
}
void store_box(const nhdyn::vecN<nhdyn::interval, nhdyn::dynamic>& r, double* lo, double* hi) {
  for (Eigen::Index i = 0; i < r.size(); ++i) lo[i] = r(i).lower(), hi[i] = r(i).upper();
}
template <class Model, class C>
batch_function nh_bounds_of(const Model& mdl, const C& c, int split) {
  const int n = mdl.dof(), m = c.m(), p = nhdyn::actuator_count(c);
  return {"torque_bounds",
          {{"q_lo", n}, {"q_hi", n}, {"eta_lo", m}, {"eta_hi", m}, {"eta_dot_lo", m}, {"eta_dot_hi", m}},
          {{"tau_lo", p}, {"tau_hi", p}},
          [mdl, c, n, m, split](const auto& in, const auto& out) {
            const auto r = nhdyn::torque_bounds<nhdyn::dynamic>(mdl, c, box_of(in[0], in[1], n), box_of(in[2], in[3], m),
                                                                box_of(in[4], in[5], m), split);
            store_box(r, out[0], out[1]);
          }};
}
template <class Model>
batch_function holonomic_bounds_of(const Model& mdl, int split) {
  const int n = mdl.dof();
  return {"torque_bounds",
          {{"q_lo", n}, {"q_hi", n}, {"qd_lo", n}, {"qd_hi", n}, {"qdd_lo", n}, {"qdd_hi", n}},
          {{"tau_lo", n}, {"tau_hi", n}},
          [mdl, n, split](const auto& in, const auto& out) {
            const auto r = nhdyn::torque_bounds<nhdyn::dynamic>(mdl, box_of(in[0], in[1], n), box_of(in[2], in[3], n),
                                                                box_of(in[4], in[5], n), split);
            store_box(r, out[0], out[1]);
          }};
}

/// Where a scene given to nhdyn.simulate names other scenes and robots: the shipped scenes
/// beside this module (build tree: build/python → build/share/nhdyn/scenes; installed:
/// lib/python3.X/dist-packages → share/nhdyn/scenes), after $NHDYN_SCENES_DIR.
nhdyn::scene::search_path scene_dirs(const std::string& module_file) {
  namespace fs = std::filesystem;
  nhdyn::scene::search_path dirs;
  if (const char* e = std::getenv("NHDYN_SCENES_DIR"); e && *e) dirs.emplace_back(e);
  const fs::path here = fs::path(module_file).parent_path();
  std::error_code ec;
  for (const fs::path& d : {here.parent_path() / "share" / "nhdyn" / "scenes",
                            here.parent_path().parent_path().parent_path() / "share" / "nhdyn" / "scenes"})
    if (fs::is_directory(d, ec)) dirs.push_back(d);
  return dirs;
}

#if NHDYN_PY_URDF
/// A Python callable as the closed loop's controller: controller(q, eta, r, ref) -> tau, with
/// ref a dict of the reference at this instant ("r", "rd", "rdd"; "q", "qd", "qdd" for a
/// joint-space reference). Called with the GIL held; a Python exception becomes the run's
/// failure (its message), never escapes into the integrator as a Python object.
struct python_controller {
  py::handle f;  // no reference counting: copied and destroyed without the GIL; the caller's object outlives the runs
  int m = 0;
  std::atomic<bool>* interrupted = nullptr;  // set by Ctrl-C (KeyboardInterrupt) in f: the study stops
  template <class T>
  Eigen::Matrix<T, Eigen::Dynamic, 1> operator()(const Eigen::Matrix<T, Eigen::Dynamic, 1>& q,
                                                 const Eigen::Matrix<T, Eigen::Dynamic, 1>& eta, const nhdyn::vec3<T>& r,
                                                 const nhdyn::task_reference<T>& ref) const {
    if constexpr (!std::is_same_v<T, double>) {
      throw nhdyn::input_error("a Python controller runs in double only (rk4 or dopri5, not rosenbrock4)");
    } else {
      py::gil_scoped_acquire gil;
      try {
        const auto arr = [](const auto& v) {
          py::array_t<double> a(py::ssize_t(v.size()));
          std::copy(v.data(), v.data() + v.size(), a.mutable_data());
          return a;
        };
        py::dict d;
        d["r"] = arr(ref.r), d["rd"] = arr(ref.rd), d["rdd"] = arr(ref.rdd);
        if (ref.q.size() > 0) d["q"] = arr(ref.q), d["qd"] = arr(ref.qd), d["qdd"] = arr(ref.qdd);
        const py::object out = f(arr(q), arr(eta), arr(r), d);
        const auto tau = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(out);
        if (!tau || tau.ndim() != 1 || tau.shape(0) != m)
          throw nhdyn::input_error("the Python controller must return " + std::to_string(m) + " numbers (one per actuator: model.tau)");
        Eigen::VectorXd t(m);
        std::copy(tau.data(), tau.data() + m, t.data());
        return t;
      } catch (py::error_already_set& e) {
        if (interrupted && (e.matches(PyExc_KeyboardInterrupt) || e.matches(PyExc_SystemExit))) *interrupted = true;
        throw std::runtime_error(std::string("Python controller: ") + e.what());
      }
    }
  }
};
#endif

/// A run's result as a dict of NumPy arrays (see nhdyn.simulate's docstring).
py::dict result_dict(const nhdyn::run_spec& spec, nhdyn::run_result& r) {
  py::dict d;
  d["name"] = r.name;
  d["success"] = r.success;
  d["failure"] = r.failure ? py::object(py::str(*r.failure)) : py::object(py::none());
  d["max_tail_error"] = r.max_tail_error;
  d["peak_tau"] = r.peak_tau;
  d["steps"] = r.steps;
  d["cpu_time_s"] = r.cpu_time_s;
  d["seed"] = spec.run_seed ? py::object(py::int_(*spec.run_seed)) : py::object(py::none());
  {  // the robot as nhdyn.view finds it again: a preset's name, or the file's absolute path
    std::error_code ec;
    const auto p = std::filesystem::absolute(spec.robot, ec);
    d["robot"] = !ec && std::filesystem::is_regular_file(p, ec) ? p.string() : spec.robot;
    py::dict held;
    for (const auto& [name, x] : spec.locked) held[py::str(name)] = x;
    d["locked"] = held;
  }
  d["columns"] = r.columns;
  const auto rows = r.rows.rows(), cols = r.rows.cols();
  py::array_t<double> data({py::ssize_t(rows), py::ssize_t(cols)});
  std::copy(r.rows.data(), r.rows.data() + rows * cols, data.mutable_data());
  d["data"] = data;
  if (r.columns.empty()) return d;  // failed before it started (a setup error): no rows
  // named blocks by the column names: t, q (n), eta (m), tau (m), r, rd (3 each), err
  const auto block = [&](const std::string& prefix, int first_hint) {
    int first = -1, count = 0;
    for (int j = first_hint; j < int(r.columns.size()); ++j)
      if (r.columns[std::size_t(j)].rfind(prefix, 0) == 0) {
        if (first < 0) first = j;
        ++count;
      } else if (first >= 0) {
        break;
      }
    py::array_t<double> a({py::ssize_t(rows), py::ssize_t(count)});
    for (Eigen::Index i = 0; i < rows; ++i)
      for (int j = 0; j < count; ++j) a.mutable_at(i, j) = r.rows(i, first + j);
    return std::pair{a, first < 0 ? first_hint : first + count};
  };
  const bool paper5 = !r.columns.empty() && r.columns[1] == "q1";
  auto [q, after_q] = block(paper5 ? "q" : "q_", 1);
  auto [eta, after_eta] = block("eta", after_q);
  auto [tau, after_tau] = block("tau", after_eta);
  d["q"] = q;
  d["eta"] = eta;
  d["tau"] = tau;
  const auto col = [&](int j) {
    py::array_t<double> a{py::ssize_t(rows)};
    for (Eigen::Index i = 0; i < rows; ++i) a.mutable_at(i) = r.rows(i, j);
    return a;
  };
  const auto three = [&](int j) {
    py::array_t<double> a({py::ssize_t(rows), py::ssize_t(3)});
    for (Eigen::Index i = 0; i < rows; ++i)
      for (int k = 0; k < 3; ++k) a.mutable_at(i, k) = r.rows(i, j + k);
    return a;
  };
  if (rows > 0 || cols > 0) {
    d["t"] = col(0);
    d["r"] = three(int(cols) - 7);
    d["rd"] = three(int(cols) - 4);
    d["err"] = col(int(cols) - 1);
  }
  return d;
}

// ---------------------------------------------------------------------------------------
// view: the page of `nhdyn view`, written by the nhdyn tool (one page writer for both)
// ---------------------------------------------------------------------------------------

/// A page nhdyn.view wrote; Jupyter shows it inline (_repr_html_: the page in an iframe).
struct page {
  std::string path;
};

/// The nhdyn tool: $NHDYN_TOOL, else the build's or the installed one this module was built
/// with, else `nhdyn` on the PATH.
std::string tool_path() {
  if (const char* e = std::getenv("NHDYN_TOOL"); e && *e) return e;
  std::error_code ec;
#ifdef NHDYN_PY_TOOL_BUILD
  if (std::filesystem::is_regular_file(NHDYN_PY_TOOL_BUILD, ec)) return NHDYN_PY_TOOL_BUILD;
#endif
#ifdef NHDYN_PY_TOOL_INSTALL
  if (std::filesystem::is_regular_file(NHDYN_PY_TOOL_INSTALL, ec)) return NHDYN_PY_TOOL_INSTALL;
#endif
  return "nhdyn";
}

/// Runs `nhdyn view ARGS` and returns the page it printed; the tool's message (naming the
/// file, joint or field at fault) becomes an InputError.
page run_view(std::vector<std::string> args) {
  args.insert(args.begin(), {tool_path(), "view"});
  py::object r;
  try {
    r = py::module_::import("subprocess").attr("run")(args, py::arg("capture_output") = true, py::arg("text") = true);
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_OSError)) throw;
    throw nhdyn::input_error("nhdyn.view: cannot run the nhdyn tool '" + args[0] + "' (" + std::string(py::str(e.value())) +
                             "): build or install it, or set NHDYN_TOOL to its path");
  }
  const auto out = r.attr("stdout").cast<std::string>(), err = r.attr("stderr").cast<std::string>();
  if (r.attr("returncode").cast<int>() != 0) {
    std::string msg = err;
    while (!msg.empty() && msg.back() == '\n') msg.pop_back();
    throw nhdyn::input_error(msg.empty() ? "nhdyn.view: the nhdyn tool failed" : msg);
  }
  if (!err.empty()) py::module_::import("sys").attr("stderr").attr("write")(err);  // notices: meshes not found
  std::string path = out.substr(0, out.find('\n'));
  return {std::filesystem::absolute(path).string()};
}

/// The runs of nhdyn.simulate (a dict or a list of them) written as `nhdyn simulate` writes a
/// folder: <name>.csv (the columns, every number in its shortest round-trip form) and
/// summary.json (name, success, robot, locked).
void write_runs(const std::vector<py::dict>& runs, const std::filesystem::path& dir) {
  nhdyn::io::ordered_json summary = {{"runs", nhdyn::io::ordered_json::array()}};
  for (const auto& d : runs) {
    for (const char* k : {"name", "columns", "data", "robot"})
      if (!d.contains(k)) throw nhdyn::input_error(std::string("nhdyn.view: a run has no '") + k + "': give nhdyn.simulate's results");
    const auto name = d["name"].cast<std::string>();
    const auto columns = d["columns"].cast<std::vector<std::string>>();
    const auto data = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(d["data"]);
    if (!data || data.ndim() != 2 || data.shape(1) != py::ssize_t(columns.size()))
      throw nhdyn::input_error("nhdyn.view: run '" + name + "': 'data' is not a rows x " + std::to_string(columns.size()) + " array");
    if (name.empty() || name.find_first_of("/\\") != std::string::npos)
      throw nhdyn::input_error("nhdyn.view: run name '" + name + "' cannot name a file");
    std::ofstream csv(dir / (name + ".csv"), std::ios::binary);
    for (std::size_t j = 0; j < columns.size(); ++j) csv << (j ? "," : "") << columns[j];
    csv << '\n';
    const double* x = data.data();
    for (py::ssize_t i = 0; i < data.shape(0); ++i) {
      for (py::ssize_t j = 0; j < data.shape(1); ++j) csv << (j ? "," : "") << nhdyn::io::format_number(x[i * data.shape(1) + j]);
      csv << '\n';
    }
    nhdyn::io::ordered_json e = {{"name", name}, {"robot", d["robot"].cast<std::string>()}};
    if (d.contains("success")) e["success"] = d["success"].cast<bool>();
    if (d.contains("locked") && py::len(d["locked"]) > 0) {
      e["locked"] = nhdyn::io::ordered_json::object();
      for (const auto& [k, v] : d["locked"].cast<py::dict>()) e["locked"][k.cast<std::string>()] = v.cast<double>();
    }
    summary["runs"].push_back(e);
  }
  std::ofstream(dir / "summary.json") << summary.dump(1);
}

/// nhdyn.view(what, path, q, package_path, max_runs): see its docstring.
page view(const py::object& what, const py::object& path, const py::object& q, const std::vector<std::string>& package_path,
          int max_runs) {
  std::vector<std::string> args;
  const auto locks_arg = [](const std::vector<std::pair<std::string, double>>& locks) {
    std::string s;
    for (const auto& [name, x] : locks) s += (s.empty() ? "" : ",") + name + "=" + nhdyn::io::format_number(x);
    return s;
  };
  std::vector<py::dict> runs;
  if (py::isinstance<py::dict>(what)) {
    runs.push_back(what.cast<py::dict>());
  } else if (py::isinstance<py::list>(what) || py::isinstance<py::tuple>(what)) {
    for (const auto& r : what) {
      if (!py::isinstance<py::dict>(r)) throw py::type_error("nhdyn.view: a list must hold nhdyn.simulate's runs (dicts)");
      runs.push_back(r.cast<py::dict>());
    }
    if (runs.empty()) throw nhdyn::input_error("nhdyn.view: no runs in the list");
  } else if (py::isinstance<model>(what)) {
    const auto& m = what.cast<const model&>();
    args = {"--model", m.source};
    if (!m.requested.empty()) args.insert(args.end(), {"--lock", locks_arg(m.requested)});
  } else if (py::isinstance<py::str>(what) || py::isinstance(what, py::module_::import("pathlib").attr("PurePath"))) {
    const std::string s = py::str(what);
    std::error_code ec;
    if (std::filesystem::is_directory(s, ec)) args = {s, "--max-runs", std::to_string(max_runs)};
    else args = {"--model", s};
  } else {
    throw py::type_error("nhdyn.view: expected a Model, a model spec or run folder (str), or nhdyn.simulate's runs, not " +
                         std::string(py::str(what.get_type().attr("__name__"))));
  }
  if (!q.is_none()) {
    if (args.empty() || args[0] != "--model") throw nhdyn::input_error("nhdyn.view: q= is for a model's pose, not for runs");
    std::string s;
    for (double x : q.cast<std::vector<double>>()) s += (s.empty() ? "" : ",") + nhdyn::io::format_number(x);
    args.insert(args.end(), {"--q", s});
  }
  for (const auto& p : package_path) args.insert(args.end(), {"--package-path", p});
  std::string out = path.is_none() ? std::string() : std::string(py::str(path));
  if (runs.empty()) {
    if (!out.empty()) args.insert(args.end(), {"--out", out});
    return run_view(args);
  }
  // runs: a scratch folder as `nhdyn simulate` writes one, the page where asked (default:
  // <first run's name>.html in the current folder)
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(py::module_::import("tempfile").attr("mkdtemp")(py::arg("prefix") = "nhdyn_view_").cast<std::string>());
  try {
    write_runs(runs, dir);
    if (out.empty()) out = runs[0]["name"].cast<std::string>() + ".html";
    args.insert(args.begin(), dir.string());
    args.insert(args.end(), {"--out", fs::absolute(out).string(), "--max-runs", std::to_string(max_runs)});
    page p = run_view(args);
    fs::remove_all(dir);
    return p;
  } catch (...) {
    std::error_code ec;
    fs::remove_all(dir, ec);
    throw;
  }
}

/// The page in an iframe (srcdoc: the page is self-contained), for Jupyter.
std::string page_html(const page& p) {
  std::ifstream f(p.path, std::ios::binary);
  if (!f) throw nhdyn::input_error("nhdyn.view: cannot read '" + p.path + "'");
  std::ostringstream s;
  s << f.rdbuf();
  std::string escaped;
  for (char c : s.str()) {
    if (c == '&') escaped += "&amp;";
    else if (c == '"') escaped += "&quot;";
    else escaped += c;
  }
  return "<iframe srcdoc=\"" + escaped + "\" style=\"width: 100%; height: 560px; border: 1px solid #ccc\" "
         "sandbox=\"allow-scripts\" title=\"nhdyn view\"></iframe>";
}

batch_function not_constrained(const model& m, const char* what) {
  throw nhdyn::model_error("model '" + m.name + "' has no constraint: " + what + " needs one (without one, inverse_dynamics is rne)");
}

}  // namespace

PYBIND11_MODULE(nhdyn, mod) {
  mod.doc() = R"(nhdyn: dynamics of manipulators and nonholonomic mobile manipulators.

Functional, as the C++ library: nhdyn.rne(model) returns a callable f(q, qd, qdd) -> tau.
Every callable takes one state (1-D float64 arrays) or a batch (2-D arrays, one state per
row; the rows are computed in C++ with the GIL released, on `threads` threads). Integer and
float32 arrays are converted to float64; other dtypes are refused. SI units, radians.
See docs/python.md.)";

  py::register_exception<nhdyn::model_error>(mod, "ModelError", PyExc_ValueError);
  py::register_exception<nhdyn::input_error>(mod, "InputError", PyExc_ValueError);
  py::register_exception<nhdyn::numerical_error>(mod, "NumericalError", PyExc_ArithmeticError);

  py::class_<model, std::shared_ptr<model>>(mod, "Model", "A robot model: a DH chain or a kinematic tree, with its constraint if any.")
      .def_property_readonly("name", [](const model& m) { return m.name; }, "the model's name")
      .def_property_readonly("dof", &model::dof, "n, the number of joint coordinates q")
      .def_property_readonly("joints", [](const model& m) { return m.joints; }, "joint names in q order")
      .def_property_readonly("locked", [](const model& m) {
            py::dict d;
            for (const auto& [name, x] : m.locked) d[py::str(name)] = x;
            return d; }, "the joints load(locked=...) held: {joint name: position}")
      .def_property_readonly("eta", [](const model& m) { return m.eta; },
                             "names of eta's entries (the independent velocities); the joint names when unconstrained")
      .def_property_readonly("tau", [](const model& m) { return m.tau; },
                             "names of tau's entries (the actuators: a wheeled_base's actuated joints, else eta's names)")
      .def_property_readonly("m", &model::m, "len(eta)")
      .def_property_readonly("p", [](const model& m) { return int(m.tau.size()); }, "len(tau), the number of actuators")
      .def_property_readonly("k", [](const model& m) { return m.dof() - m.m(); }, "number of constraints")
      .def_property_readonly("constrained", &model::constrained, "whether the model has a nonholonomic constraint")
      .def_property_readonly("source", [](const model& m) { return m.source; }, "what it was loaded from")
      .def("__repr__", [](const model& m) {
        return "<nhdyn.Model '" + m.name + "': dof " + std::to_string(m.dof()) + ", k " + std::to_string(m.dof() - m.m()) + ">";
      });

  py::class_<batch_function>(mod, "Function", "A dynamics function of a model: call it on arrays.")
      .def("__call__", &batch_function::call, py::arg("threads") = 1,
           "f(*arrays, threads=1): one state (1-D arrays) or one per row (2-D arrays, same number of rows)")
      .def_property_readonly("signature", &batch_function::signature, "argument and result names and sizes")
      .def("__repr__", [](const batch_function& f) { return "<nhdyn.Function " + f.signature() + ">"; });

  mod.def("presets", [] { return nhdyn::io::preset_names(); }, "The names nhdyn.load knows without a file.");
  mod.def("load", &load, py::arg("spec"), py::arg("strict") = false, py::arg("locked") = std::map<std::string, double>{},
          R"(load(spec, strict=False, locked={}) -> Model

spec: a preset name (nhdyn.presets()), a JSON model file, a URDF file (*.urdf) or a robot
file (JSON with a "urdf" key: a URDF on a wheeled base with its constraint). strict: a
non-physical URDF inertia is an error instead of a warning on stderr. locked: {joint name
or shell glob: position [rad or m]}: those joints held there, their links merged into their
parents (a DH model so held becomes a tree with joints joint1..; a constraint's joints
cannot be locked; a JSON model's own "locked" is applied too); Model.locked lists them. Raises ModelError with the file, link and field at fault.)");
  mod.def("rne", [](const model& m, const std::optional<py::list>& w, const py::object& terms, double smooth) {
            if (!terms.is_none() || smooth != 0) {
              const auto t = terms_from(terms.is_none() ? py::str("gravity,velocity,armature") : terms, smooth);
              return m.dispatch([&](const auto& x, const auto&) { return rne_terms_of(x, t, w); }, [&](const auto& x) { return rne_terms_of(x, t, w); });
            }
            if (w && !w->empty()) return m.dispatch([&](const auto& x, const auto&) { return rne_wrenches_of(x, *w); }, [&](const auto& x) { return rne_wrenches_of(x, *w); });
            return m.dispatch([](const auto& x, const auto&) { return rne_of(x); }, [](const auto& x) { return rne_of(x); }); },
          py::arg("model"), py::arg("wrenches") = py::none(), py::arg("terms") = py::none(), py::arg("smooth") = 0.0,
          R"(rne(model, wrenches=None, terms=None, smooth=0) -> f(q, qd, qdd) -> tau

The holonomic recursive Newton-Euler inverse dynamics tau = M(q) qdd + C(q, qd) qd + g(q)
(+ armature qdd), n entries each [rad, rad/s, rad/s^2 or m, m/s, m/s^2 -> N m or N]. For a
constrained model: of its stationary robot (all n joints). wrenches: external wrenches the
environment applies, a list of {"body": name, "frame": "world" or "body", "point": [m, in
the body frame], "force": [N], "moment": [N m]}: tau - sum J^T [f; m].
terms: the terms to include, a list of names or a comma-separated string of gravity,
velocity, armature, friction (or "all", "none"); None: gravity, velocity, armature (friction
only when asked, as the tool's --terms). smooth: with friction, the Coulomb part smoothed
at this velocity scale v_s > 0 [rad/s or m/s] (0: the exact sign law).)");
  mod.def("mass_matrix", [](const model& m) { return m.dispatch([](const auto& x, const auto&) { return mass_matrix_of(x); }, [](const auto& x) { return mass_matrix_of(x); }); },
          py::arg("model"), "mass_matrix(model) -> f(q) -> M (n x n, CRBA) [kg m^2, kg]");
  mod.def("bias", [](const model& m) { return m.dispatch([](const auto& x, const auto&) { return bias_of(x); }, [](const auto& x) { return bias_of(x); }); },
          py::arg("model"), "bias(model) -> f(q, qd) -> h = C(q, qd) qd + g(q) (n entries)");
  mod.def("inverse_dynamics",
          [](const model& m, const std::optional<py::list>& w, const py::object& terms, double smooth) {
            if (!terms.is_none() || smooth != 0) {
              const auto t = terms_from(terms.is_none() ? py::str("gravity,velocity,armature") : terms, smooth);
              return m.dispatch([&](const auto& x, const auto& c) { return nh_id_terms_of(x, c, t, w); },
                                [&](const auto& x) { return rne_terms_of(x, t, w); });
            }
            if (w && !w->empty())
              return m.dispatch([&](const auto& x, const auto& c) { return nh_id_wrenches_of(x, c, *w); },
                                [&](const auto& x) { return rne_wrenches_of(x, *w); });
            return m.dispatch([](const auto& x, const auto& c) { return nh_id_of(x, c); }, [](const auto& x) { return rne_of(x); }); },
          py::arg("model"), py::arg("wrenches") = py::none(), py::arg("terms") = py::none(), py::arg("smooth") = 0.0,
          R"(inverse_dynamics(model, wrenches=None, terms=None, smooth=0) -> f(q, eta, eta_dot) -> tau

The paper's nonholonomic inverse dynamics, project o rne o lift: q (n), eta and eta_dot (m,
named by model.eta) -> tau (m actuator forces). A model without a constraint: eta = qd, and
this is rne. wrenches: external wrenches as for rne, inside the pipeline (lift | rne |
wrenches | project). terms, smooth: as for rne (friction: lift | rne + friction | project).)");
  mod.def("lift",
          [](const model& m) {
            return m.dispatch([](const auto& x, const auto& c) { return lift_of(x, c); },
                              [&](const auto&) { return not_constrained(m, "lift"); });
          },
          py::arg("model"),
          R"(lift(model) -> f(q, eta, eta_dot) -> (q, qd, qdd)

The first stage of the paper's inverse dynamics: the stationary robot's state xi = (q, S eta,
S eta_dot + Sdot eta) (n entries each). inverse_dynamics is project o rne o lift; compose your
own in Python, e.g. xq, xqd, xqdd = lift(q, eta, eta_dot); project(q, rne(xq, xqd, xqdd) +
friction(xqd)).)");
  mod.def("project",
          [](const model& m) {
            return m.dispatch([](const auto& x, const auto& c) { return project_of(x, c); },
                              [&](const auto&) { return not_constrained(m, "project"); });
          },
          py::arg("model"),
          R"(project(model) -> f(q, v) -> tau

The last stage: the actuator forces tau = (S^T E)^-1 S^T v (m entries) that produce the
generalized forces v (n entries) of the stationary robot along the admissible motions.)");
  mod.def("friction",
          [](const model& m, double smooth) {
            return m.dispatch([&](const auto& x, const auto&) { return friction_of(x, smooth); }, [&](const auto& x) { return friction_of(x, smooth); });
          },
          py::arg("model"), py::arg("smooth") = 0.0,
          R"(friction(model, smooth=0) -> f(qd) -> tau_f (n entries) [N m or N]

The joints' friction from the model (JSON "friction"/"motor", URDF <dynamics damping
friction>): tau_f,i = B_i qd_i + c_i(qd_i), c = c+ for qd > 0, c- for qd < 0, 0 at rest.
smooth = v_s > 0 [rad/s or m/s]: c+ s(qd) for qd > 0 and -c- s(qd) below, s = qd /
sqrt(qd^2 + v_s^2), instead (continuous through rest). What the
drives must add to rne's torque: rne(model)(q, qd, qdd) + friction(model)(qd).)");
  mod.def("generalized_force",
          [](const model& m, const py::list& w) {
            return m.dispatch([&](const auto& x, const auto&) { return generalized_force_of(x, w); },
                              [&](const auto& x) { return generalized_force_of(x, w); });
          },
          py::arg("model"), py::arg("wrenches"),
          R"(generalized_force(model, wrenches) -> f(q) -> Q (n entries)

Q = sum J^T [f; m] of the external wrenches (as for rne) at q: what they add to the
generalized forces (rne with them is rne - Q).)");
  // The loop a C++ user writes around the library's call (rows copied into Eigen vectors,
  // τ stored row by row), compiled in this module with its flags: the reference that
  // bench/python_bench.py measures the batched call against, in the same process on the
  // same arrays (issue 16: 10⁶ paper5 inverse dynamics from Python within 1.5× of it).
  mod.def("_fast_path_calls", [] { return batch_function::fast_calls.load(); },
          "How many one-state calls took the in-place path so far (tests check which path ran).");
  mod.def("_cxx_loop_inverse_dynamics",
          [](const model& m, const py::array_t<double, py::array::c_style | py::array::forcecast>& Q,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& E,
             const py::array_t<double, py::array::c_style | py::array::forcecast>& ED) {
            const int n = m.dof(), k = m.m(), p = int(m.tau.size());
            if (Q.ndim() != 2 || E.ndim() != 2 || ED.ndim() != 2 || Q.shape(1) != n || E.shape(1) != k || ED.shape(1) != k ||
                E.shape(0) != Q.shape(0) || ED.shape(0) != Q.shape(0))
              throw nhdyn::input_error("_cxx_loop_inverse_dynamics: rows of q (n), eta and eta_dot (m)");
            const py::ssize_t rows = Q.shape(0);
            py::array_t<double> out({rows, py::ssize_t(p)});
            const double *q = Q.data(), *e = E.data(), *ed = ED.data();
            double* o = out.mutable_data();
            py::gil_scoped_release release;
            m.dispatch(
                [&](const auto& x, const auto& c) {
                  const auto f = nhdyn::inverse_dynamics(x, c);
                  VectorXd qv(n), ev(k), edv(k);
                  for (py::ssize_t i = 0; i < rows; ++i) {
                    qv = cmap(q + i * n, n), ev = cmap(e + i * k, k), edv = cmap(ed + i * k, k);
                    vmap(o + i * p, p) = f(qv, ev, edv);
                  }
                  return 0;
                },
                [&](const auto&) -> int { throw nhdyn::input_error("_cxx_loop_inverse_dynamics: needs a constrained model"); });
            return out;
          },
          py::arg("model"), py::arg("q"), py::arg("eta"), py::arg("eta_dot"),
          "Benchmark reference (bench/python_bench.py): a plain C++ loop of the library's inverse dynamics over rows.");
  mod.def("inverse_dynamics_with_forces",
          [](const model& m) { return m.dispatch([](const auto& x, const auto& c) { return nh_id_forces_of(x, c); },
                                                  [&](const auto&) { return not_constrained(m, "inverse_dynamics_with_forces"); }); },
          py::arg("model"), "inverse_dynamics_with_forces(model) -> f(q, eta, eta_dot) -> (tau, lambda): lambda the k constraint forces");
  mod.def("linearize",
          [](const model& m) { return m.dispatch([](const auto& x, const auto& c) { return nh_linearize_of(x, c); }, [](const auto& x) { return holonomic_linearize_of(x); }); },
          py::arg("model"),
          R"(linearize(model) -> f(q, eta_or_qd, tau) -> (A, B)

The exact linearisation x_dot = A dx + B du of the forward dynamics (dual numbers, from the
inverse dynamics by the implicit-function theorem). Constrained: x = (q, eta), u = tau,
A (n+m) x (n+m), B (n+m) x p (p = len(model.tau)). Holonomic: x = (q, qd), A 2n x 2n, B 2n x n.)");
  mod.def("state_derivative",
          [](const model& m) {
            return m.dispatch([](const auto& x, const auto& c) { return nh_state_derivative_of(x, c); },
                              [](const auto& x) { return holonomic_state_derivative_of(x); });
          },
          py::arg("model"),
          R"(state_derivative(model) -> f(q, eta_or_qd, tau) -> xdot

For integrators: constrained x = (q, eta), xdot = (S(q) eta, eta_dot) (n + m entries);
holonomic x = (q, qd), xdot = (qd, qdd) (2n entries).)");
  mod.def("frame",
          [](const model& m, const std::string& name) {
            return m.dispatch([&](const auto& x, const auto&) { return frame_of(x, name); }, [&](const auto& x) { return frame_of(x, name); });
          },
          py::arg("model"), py::arg("name"),
          R"(frame(model, name) -> f(q) -> T (4 x 4)

The pose of a body or frame in the base (world) frame: [[R, p], [0, 0, 0, 1]], p in m. Names:
a URDF's links and merged frames; a DH model's base, link1 ... linkN.)");
  mod.def("jacobian",
          [](const model& m, const std::string& name, const std::array<double, 3>& point) {
            const Eigen::Vector3d p(point[0], point[1], point[2]);
            return m.dispatch([&](const auto& x, const auto&) { return jacobian_of(x, name, p); },
                              [&](const auto& x) { return jacobian_of(x, name, p); });
          },
          py::arg("model"), py::arg("name"), py::arg("point") = std::array<double, 3>{0, 0, 0},
          R"(jacobian(model, name, point=(0, 0, 0)) -> f(q) -> J (6 x n)

The geometric Jacobian of a point fixed on a body or frame (point in that frame, m), in the
base frame: rows 0-2 the point's velocity [m/s], rows 3-5 the angular velocity [rad/s] per
unit qd.)");
  mod.def("forward_dynamics",
          [](const model& m, const std::optional<py::list>& w) {
            if (w && !w->empty())
              return m.dispatch([&](const auto& x, const auto& c) { return nh_fd_wrenches_of(x, c, *w); },
                                [&](const auto& x) { return holonomic_fd_wrenches_of(x, *w); });
            return m.dispatch([](const auto& x, const auto& c) { return nh_fd_of(x, c); }, [](const auto& x) { return holonomic_fd_of(x); }); },
          py::arg("model"), py::arg("wrenches") = py::none(),
          R"(forward_dynamics(model, wrenches=None) -> f(q, eta_or_qd, tau) -> eta_dot or qdd

wrenches: external wrenches as for rne, acting on the robot.

Constrained: eta_dot = M_eta^-1 (S^T E tau - h_eta) (m entries). Holonomic: qdd (n entries),
by CRBA + LDL^T or ABA (chosen as the C++ forward_dynamics does). Raises NumericalError for
a singular mass matrix.)");
  mod.def("torque_bounds",
          [](const model& m, int split) {
            if (split < 0 || split > 30) throw nhdyn::input_error("torque_bounds: split must be in 0…30, not " + std::to_string(split));
            return m.dispatch([split](const auto& x, const auto& c) { return nh_bounds_of(x, c, split); },
                              [split](const auto& x) { return holonomic_bounds_of(x, split); });
          },
          py::arg("model"), py::arg("split") = 0,
          R"(torque_bounds(model, split=0) -> f(q_lo, q_hi, eta_lo, eta_hi, eta_dot_lo, eta_dot_hi) -> (tau_lo, tau_hi)

Guaranteed bounds (interval arithmetic, outward rounding) on the torques over a box of
states: every tau(q, eta, eta_dot) with q in [q_lo, q_hi], ... lies in [tau_lo, tau_hi]
[N, N m]. Constrained models: the nonholonomic tau (m entries); holonomic:
f(q_lo, q_hi, qd_lo, qd_hi, qdd_lo, qdd_hi) -> rne bounds (n entries). `split` bisects the
box 2^split times (tighter bounds, 2^split evaluations). Batches: one box per row. Raises
InputError for lo > hi or NaN, NumericalError for a box too wide to bound.)");
  py::class_<page>(mod, "Page", "A page nhdyn.view wrote: its path; shown inline in Jupyter (an iframe of the page).")
      .def_readonly("path", &page::path, "the page's absolute path")
      .def("__fspath__", [](const page& p) { return p.path; })
      .def("__str__", [](const page& p) { return p.path; })
      .def("__repr__", [](const page& p) { return "nhdyn.Page('" + p.path + "')"; })
      .def("_repr_html_", &page_html, "the page in an iframe (its srcdoc), for Jupyter");
  mod.def("view", &view, py::arg("what"), py::arg("path") = py::none(), py::arg("q") = py::none(),
          py::arg("package_path") = std::vector<std::string>{}, py::arg("max_runs") = 40,
          R"(view(what, path=None, q=None, package_path=[], max_runs=40) -> Page

One self-contained HTML page of a robot or of its runs (three.js; nothing is fetched when it
is opened), written by the nhdyn tool's `view` (docs/tool.md): the robot from its URDF (a DH
model as rods between its frames), the floor, the base's trace, the task path and its
reference, a time slider, q and eta at the cursor, plots of the error and tau; a study's
runs listed or overlaid. what: a Model (its spec and locked=), a model spec (str), an
`nhdyn simulate` output folder, or nhdyn.simulate's runs (a dict or a list of them). path:
where the page goes (default: the model's or first run's name .html in the current folder,
or RUN_DIR/view.html). q: a pose for a model (nhdyn order; default zeros). package_path:
folders for package:// meshes. Returns a Page (str() is its path); in Jupyter the page shows
inline. The tool is $NHDYN_TOOL, the one built or installed with this module, or `nhdyn` on
the PATH. Raises InputError with the tool's message (the file, joint or field at fault).)");
  mod.def("simulate",
          [](const py::object& scene, int threads, const py::object& controller) {
            const std::string module_file = py::module_::import("nhdyn").attr("__file__").cast<std::string>();
            auto dirs = scene_dirs(module_file);
            nhdyn::scene::json j;
            if (py::isinstance<py::str>(scene) || py::isinstance(scene, py::module_::import("pathlib").attr("PurePath"))) {
              auto opened = nhdyn::scene::open(py::str(scene).cast<std::string>(), dirs);
              j = std::move(opened.j);
              dirs = std::move(opened.dirs);
            } else {
              const std::string text = py::module_::import("json").attr("dumps")(scene).cast<std::string>();
              j = nhdyn::io::parse_strict<nhdyn::input_error>(text, "scene (a dict): ");
            }
            const auto specs = nhdyn::scene::expand(j, dirs);
            std::vector<nhdyn::run_result> results;
            if (!controller.is_none()) {
#if NHDYN_PY_URDF
              if (!PyCallable_Check(controller.ptr())) throw nhdyn::input_error("nhdyn.simulate: controller must be callable");
              std::atomic<bool> interrupted{false};
              const auto with_python = [&](const nhdyn::run_spec& s) {
                if (interrupted) throw nhdyn::input_error("not run: interrupted (KeyboardInterrupt)");
                return nhdyn::simulate_scene_with(s, [&](const auto&, const auto& c, int, const auto&, const auto&, const auto&) {
                  return python_controller{controller, nhdyn::actuator_count(c), &interrupted};
                });
              };
              {
                py::gil_scoped_release release;  // the callbacks take it back
                results = nhdyn::run_batch(specs, 1, [](std::size_t, nhdyn::run_result&) {}, with_python);
              }
              if (interrupted) {
                PyErr_SetNone(PyExc_KeyboardInterrupt);
                throw py::error_already_set();
              }
#else
              throw nhdyn::input_error("nhdyn.simulate: a Python controller needs nhdyn built with URDF support");
#endif
            } else {
              py::gil_scoped_release release;
#if NHDYN_PY_URDF
              results = nhdyn::run_batch(specs, unsigned(std::max(0, threads)), [](std::size_t, nhdyn::run_result&) {},
                                         nhdyn::simulate_scene);
#else
              results = nhdyn::run_batch(specs, unsigned(std::max(0, threads)), [](std::size_t, nhdyn::run_result&) {});
#endif
            }
            py::list out;
            for (std::size_t i = 0; i < results.size(); ++i) out.append(result_dict(specs[i], results[i]));
            return out;
          },
          py::arg("scene"), py::arg("threads") = 0, py::arg("controller") = py::none(),
          R"(simulate(scene, threads=0, controller=None) -> list of dicts, one per run

Runs a scene, study or suite (docs/simulation.md): `scene` is a file path, the name of a
shipped scene ("paper-circle", "paper", "mobile-manipulator-circle", ...) or a dict in the
scene format; a study's runs go on `threads` threads (0: all cores) with the GIL released.
Each run: {"name", "success", "failure" (str or None), "max_tail_error" [m], "peak_tau",
"steps", "cpu_time_s", "seed" (Monte Carlo runs), "columns" (the CSV's names), "data" (rows x
columns), and the blocks "t" [s], "q", "eta", "tau", "r", "rd" [m] (rows x 3), "err" [m]}.
A failing run is reported, not raised: "success" False and "failure" the reason (a run that
cannot be set up — an unknown frame, a wrong initial size — says "setup: ..." and has no
rows); a scene file that cannot be read or parsed raises InputError naming the field.

controller: a Python function controller(q, eta, r, ref) -> tau (p = len(model.tau) entries) used instead of
the scene's controller, on every run (one at a time: it holds the GIL): q (n), eta (m) the
state, r (3) the measured task point [m], ref a dict of the reference at this instant: "r",
"rd", "rdd" (3 each) and, for a joint_spline reference, "q", "qd", "qdd" (n each). The
scene's robot runs as a kinematic tree (paper5 included), integrated by rk4 or dopri5. An
exception in it fails the run with its message.)");
}
