#pragma once
/// \file tool.hpp
/// The `nhdyn` command-line tool's shared parts: the subcommand record, argument parsing,
/// model loading and the one line-processing loop every line-oriented subcommand uses.
///
/// Adding a subcommand: write examples/nhdyn_tool/<name>.cpp defining
/// `nhdyn_tool::command nhdyn_tool::command_<name>()`, and add `X(<name>)` to the list in
/// main.cpp. A line-oriented subcommand starts with `start_model_command` (or, with more
/// options, its own CLI::App, `parse_command_line` and `load_model`), and hands a
/// `line_handler` to `run_lines`.
#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <optional>
#include <variant>
#include <nhdyn/constraints/constraint.hpp>
#include <nhdyn/dynamics/friction.hpp>
#include <nhdyn/dynamics/terms.hpp>
#include <nhdyn/dynamics/tree.hpp>
#include <nhdyn/dynamics/wrench.hpp>
#include <nhdyn/io/json.hpp>
#include <nhdyn/model/tree.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace nhdyn_tool {

using json = nlohmann::json;                  // an input line, parsed
using ordered_json = nlohmann::ordered_json;  // an output line, keys in the order written

/// A subcommand: `run` gets the arguments after its name and returns the exit status.
struct command {
  std::string_view name;
  std::string_view summary;  ///< one line, for `nhdyn --help`
  std::string_view usage;    ///< the full text of `nhdyn <name> --help`
  int (*run)(const std::vector<std::string>& args);
};

/// Thrown for a bad command line; main prints it with the usage hint, exit status 2.
struct usage_error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Parses a subcommand's arguments with CLI11, strictly: unknown options, a missing or
/// repeated value, a number that is not wholly a number, and a value out of range are
/// usage_errors (exit status 2); `--` ends the options (what follows is positional).
/// `-h`/`--help` prints `usage` on stdout and returns false (the subcommand then exits 0).
bool parse_command_line(CLI::App& app, const std::vector<std::string>& args, std::string_view usage);

/// An option taking a decimal integer (digits only, an optional leading '-'; 010 is ten)
/// within [lo, hi]; anything else is a usage_error naming the option.
CLI::Option* add_integer_option(CLI::App& app, const std::string& name, int& value, int lo, int hi);

/// The model named by --model (a preset name, a model file, or a shipped model's name).
/// Throws nhdyn::error with a message naming the file, link and field.
nhdyn::io::model<double> load_model(const std::string& spec);

/// The start of every line-oriented subcommand whose only option is --model: parses args,
/// answers --help by printing `usage` (then returns no model: the subcommand exits 0),
/// rejects positional arguments (usage_error), and loads the model.
std::optional<nhdyn::io::model<double>> start_model_command(const std::vector<std::string>& args,
                                                            std::string_view usage);

/// A model as the tool loads it: a DH model (preset, JSON file; with its constraint if any)
/// or a kinematic tree from a URDF file. Exactly one is set.
struct any_model {
  std::optional<nhdyn::io::model<double>> dh;
  std::optional<nhdyn::tree<double>> tree;
  /// A robot file's constraint on the tree (differential_drive, rolling_wheels or bicycle).
  std::optional<nhdyn::base_constraint> tree_constraint;
  /// The joints held (the robot file's "locked" and --lock), by name, with their positions.
  std::vector<std::pair<std::string, double>> locked;
  /// The terms the computation includes (--terms, --smooth-coulomb; the model's armature is
  /// already dropped when they leave it out).
  nhdyn::terms terms;
  const std::string& name() const { return dh ? dh->chain.name() : tree->name(); }
};
/// Calls `constrained(model, c)` for a model with a constraint (a DH chain with its
/// constraint, or a robot file's tree with its constraint type) and `holonomic(model)`
/// otherwise (a DH chain or a URDF tree), and returns what it returns.
template <class Constrained, class Holonomic>
int dispatch(const any_model& a, const Constrained& constrained, const Holonomic& holonomic) {
  if (a.tree) {
    if (a.tree_constraint) return std::visit([&](const auto& c) { return constrained(*a.tree, c); }, *a.tree_constraint);
    return holonomic(*a.tree);
  }
  if (a.dh->constraint) return constrained(a.dh->chain, *a.dh->constraint);
  return holonomic(a.dh->chain);
}

/// q's entries for a model: nq of a tree (one more than dof for a floating base,
/// model/floating.hpp), dof of a chain.
template <class Model>
int nq_of(const Model& m) {
  if constexpr (requires { m.nq(); })
    return m.nq();
  else
    return m.dof();
}
/// Refuses a floating tree in a command that does not take one yet, naming the command.
template <class Model>
void refuse_floating(const Model& m, std::string_view command) {
  if constexpr (requires { m.floating(); })
    if (m.floating())
      throw nhdyn::input_error("model '" + m.name() + "' has a floating base, which `nhdyn " + std::string(command) +
                               "` does not take yet (model, id and fd do)");
}

/// Calls f(dyn) with dyn the stage in rne's place as the terms say: rne(model, t.rne()), or
/// rne(model, t.rne()) + friction(model, t.coulomb) (a sum_fn: its `b` is the friction).
template <class Model, class F>
int with_dynamics(const Model& model, const nhdyn::terms& t, const F& f) {
  auto r = nhdyn::rne(model, t.rne());
  if (t.friction) return f(r + nhdyn::friction(model, t.coulomb));
  return f(r);
}

/// The friction the terms ask for (friction(model, t.coulomb)), if they include it.
template <class Model>
std::optional<nhdyn::friction_fn> friction_of(const Model& model, const nhdyn::terms& t) {
  if (!t.friction) return std::nullopt;
  return nhdyn::friction(model, t.coulomb);
}

/// Whether MODEL names a URDF file (its extension is .urdf, any case).
bool is_urdf(const std::string& spec);
/// Whether MODEL names a robot file (a JSON object with a "urdf" key).
bool is_robot_file(const std::string& spec);
/// load_model, URDF files (*.urdf) and robot files (JSON with a "urdf" key); `strict`: a non-physical inertia in a URDF is an error
/// instead of a warning on stderr; `locks`: joints held at positions (names or globs,
/// nhdyn::lock), for every model (a DH chain with joints held, by --lock or its file's
/// "locked", becomes a tree: io::as_robot).
any_model load_any_model(const std::string& spec, bool strict = false,
                         const std::vector<std::pair<std::string, double>>& locks = {});
/// The value of --lock, 'NAME=POSITION,GLOB=POSITION,...': usage_error naming a bad entry.
std::vector<std::pair<std::string, double>> parse_locks(const std::string& text);
/// start_model_command for the subcommands that take any model:
/// `--model MODEL [--strict] [--lock 'NAME=POS,...']`, and with `takes_terms`
/// `[--terms LIST] [--smooth-coulomb VS]` (any_model::terms; an unknown term is a usage_error).
std::optional<any_model> start_any_model_command(const std::vector<std::string>& args, std::string_view usage,
                                                 bool takes_terms = false);

/// The help of start_any_model_command's options, the end of each such subcommand's usage.
inline constexpr std::string_view model_options_help =
    R"(  --strict: a URDF inertia that is not physically valid is an error instead of a warning.
  --lock 'NAME=POS,GLOB=POS,...': hold those joints (joint names or shell globs: *, ?,
    [..]; a DH model's are joint1, joint2, ...) at the positions [rad or m], their links
    merged into their parents; the model then has the other joints only (any model; a DH
    chain so held is a tree; a constraint's joints cannot be locked; `nhdyn model` lists
    what was locked).
)";
/// The help of --terms and --smooth-coulomb.
inline constexpr std::string_view terms_help =
    R"(  --terms LIST: the terms of the equations of motion to include, comma-separated:
    gravity   g(q)
    velocity  C(q, qd) qd (Coriolis and centrifugal)
    armature  the joints' reflected rotor inertia G^2 J_m (a DH link's "armature" or
              "motor", a robot file's "drives"; a URDF alone has none)
    friction  the joints' viscous and Coulomb friction (a link's "friction" or "motor", a
              URDF joint's <dynamics damping friction>)
    or all, or none. Default: gravity,velocity,armature (the rigid-body terms and armature,
    as KDL's and Pinocchio's inverse dynamics): friction only when asked.
  --smooth-coulomb VS: with friction, the Coulomb part c*qd/sqrt(qd^2 + VS^2) (VS > 0 in
    rad/s or m/s) instead of the exact sign law (0 at rest, as the Robotics Toolbox).
)";

/// `nhdyn view`'s page of an `nhdyn simulate` folder (view.cpp): the runs' CSVs in
/// summary.json's order (at most max_runs), the robot `model` with `locks` held (or, when
/// `model` is empty, summary.json's "robot" and "locked"), meshes through package_paths;
/// writes `out` (empty: run_dir/view.html) and returns its path. Throws nhdyn::error naming
/// the file at fault.
std::filesystem::path write_view_page(const std::filesystem::path& run_dir, const std::string& model,
                                      const std::filesystem::path& out, const std::vector<std::string>& package_paths,
                                      int max_runs = 40, const std::vector<std::pair<std::string, double>>& locks = {});

/// Where the tool's shipped data lives: `share/nhdyn` beside the folder of the running
/// `nhdyn` (its `bin/`), as `cmake --install` and the build tree (`build/bin/nhdyn`,
/// `build/share/nhdyn`) lay it out.
std::filesystem::path data_dir();

// ---------------------------------------------------------------------------------------
// Lines
// ---------------------------------------------------------------------------------------

/// One input line's object, with typed accessors that throw nhdyn::input_error naming the
/// key (e.g. "'q' has 4 entries; the model needs 5").
class line {
 public:
  explicit line(json j) : j_(std::move(j)) {}
  const json& raw() const { return j_; }
  bool has(std::string_view key) const { return j_.contains(key); }
  /// Throws unless the keys are exactly `keys` (naming missing and unknown ones).
  void expect_keys(const std::vector<std::string>& keys) const;
  /// A vector of n finite numbers (n < 0: any length ≥ 1).
  Eigen::VectorXd vector(std::string_view key, int n) const;
  /// A list of n intervals [lo, hi] with lo ≤ hi, finite, as an n×2 matrix.
  Eigen::MatrixX2d intervals(std::string_view key, int n) const;
  /// A finite number.
  double number(std::string_view key) const;
  /// A non-negative integer no larger than `max`.
  int integer(std::string_view key, int max) const;

 private:
  json j_;
};

/// The line's optional "f_ext": a list of {"body": NAME, "frame": "world" | "body" (default
/// world), "point": [x, y, z], "force": [..], "moment": [..]} (each vector optional, zero by
/// default; point in the named frame, force and moment in the frame "frame" says); empty if
/// the key is absent. Errors name the entry and the field.
using wrench_maker = std::function<nhdyn::wrench<double>(const std::string& body, nhdyn::wrench_frame frame,
                                                          const Eigen::Vector3d& point, const Eigen::Vector3d& force,
                                                          const Eigen::Vector3d& moment)>;
std::vector<nhdyn::wrench<double>> line_wrenches(const line& l, const wrench_maker& make);
/// line_wrenches on a model: bodies and frames named as nhdyn::wrench_on takes them.
template <class Model>
std::vector<nhdyn::wrench<double>> wrenches_of(const line& l, const Model& model) {
  return line_wrenches(l, [&](const std::string& body, nhdyn::wrench_frame frame, const Eigen::Vector3d& point,
                              const Eigen::Vector3d& force, const Eigen::Vector3d& moment) {
    return nhdyn::wrench_on(model, body, frame, point, force, moment);
  });
}
/// `keys`, and "f_ext" if the line has it (the optional key of id and fd lines).
inline std::vector<std::string> with_f_ext(const line& l, std::vector<std::string> keys) {
  if (l.has("f_ext")) keys.push_back("f_ext");
  return keys;
}

/// Maps one parsed input line to its output object. Throws (any std::exception) to report
/// the line as an error.
using line_handler = std::function<ordered_json(const line&)>;

/// The loop of every line-oriented subcommand: reads JSON lines from `in`, writes one line
/// per input line to `out`, in order, flushed (so the tool can be driven interactively).
/// A line that is not a JSON object, or whose handler throws, gets {"error": "line N: …"}
/// and the loop goes on. An empty (or blank) line is an error line too, so input line k is
/// always output line k. Returns the exit status: 0 if every line succeeded, 1 otherwise.
int run_lines(std::istream& in, std::ostream& out, const line_handler& handle);

/// JSON helpers for output: arrays of numbers, row-major matrices (printed in the
/// shortest form that reads back to the same double by run_lines; a NaN or Inf makes the line an error naming the key).
ordered_json to_json(const Eigen::VectorXd& v);
ordered_json to_json(const Eigen::MatrixXd& m);

}  // namespace nhdyn_tool
