/// \file tool.cpp
/// The shared parts of the `nhdyn` tool: options, model loading, the line loop.
#include "tool.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#ifdef NHDYN_TOOL_URDF
#include <nhdyn/io/robot_file.hpp>
#endif
#include <cmath>
#include <cstdlib>
#include <iostream>

namespace nhdyn_tool {

bool parse_command_line(CLI::App& app, const std::vector<std::string>& args, std::string_view usage) {
  app.set_help_flag("-h,--help");
  app.allow_extras(false);
  app.positionals_at_end(false);
  std::vector<const char*> argv{"nhdyn"};
  for (const auto& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::CallForHelp&) {
    std::cout << usage;
    return false;
  } catch (const CLI::ExtrasError&) {
    std::string msg = "unexpected argument(s):";
    for (const auto& a : app.remaining()) msg += " " + a;
    throw usage_error(msg);
  } catch (const CLI::ParseError& e) {
    throw usage_error(e.what());
  }
  return true;
}

CLI::Option* add_integer_option(CLI::App& app, const std::string& name, int& value, int lo, int hi) {
  return app.add_option(name, value)->transform(CLI::Validator(
      [lo, hi](std::string& s) -> std::string {  // a transform: it may rewrite s
        const std::size_t digits = s.size() - (!s.empty() && s[0] == '-');
        if (digits == 0 || digits > 18 || s.find_first_not_of("0123456789", s[0] == '-' ? 1 : 0) != std::string::npos)
          return "'" + s + "' is not a decimal integer";
        const long long v = std::stoll(s);  // decimal (CLI11 alone would read 010 as octal 8)
        if (v < lo || v > hi)
          return "'" + s + "' is outside " + std::to_string(lo) + "…" + std::to_string(hi);
        s = std::to_string(v);
        return {};
      },
      "INTEGER in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", "integer_in"));
}

std::filesystem::path data_dir() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  // Never the current folder: without /proc/self/exe there is no shipped data to find.
  return ec ? std::filesystem::path() : exe.parent_path().parent_path() / "share" / "nhdyn";
}

bool is_urdf(const std::string& spec) {
  std::string ext = std::filesystem::path(spec).extension().string();
  for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".urdf";
}

bool is_robot_file(const std::string& spec) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(spec, ec)) return false;
  std::ifstream in(spec);
  const auto j = json::parse(in, nullptr, false);
  return j.is_object() && j.contains("urdf");
}

std::vector<std::pair<std::string, double>> parse_locks(const std::string& text) {
  std::vector<std::pair<std::string, double>> out;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find(',', start), text.size());
    const std::string entry = text.substr(start, end - start);
    const std::size_t eq = entry.rfind('=');
    const std::string value = eq == std::string::npos ? "" : entry.substr(eq + 1);
    char* stop = nullptr;
    const double x = value.empty() ? 0.0 : std::strtod(value.c_str(), &stop);
    if (eq == std::string::npos || eq == 0 || value.empty() || stop != value.c_str() + value.size() || !std::isfinite(x))
      throw usage_error("--lock: '" + entry + "' is not NAME=POSITION (a joint name or glob, '=', a finite number)");
    out.emplace_back(entry.substr(0, eq), x);
    start = end + 1;
  }
  return out;
}

any_model load_any_model(const std::string& spec, bool strict, const std::vector<std::pair<std::string, double>>& locks) {
  const bool robot = !is_urdf(spec) && is_robot_file(spec);
  if (!is_urdf(spec) && !robot) {
    auto m = load_model(spec);
    if (locks.empty() && m.locked.empty()) return {std::move(m), std::nullopt, std::nullopt, {}, {}};
#ifdef NHDYN_TOOL_URDF
    // a DH chain with joints held is a tree (io::as_robot): the file's "locked", then --lock
    auto r = nhdyn::io::lock_robot(nhdyn::io::as_robot(m, "model '" + spec + "', locked: "), locks, "--lock: ");
    std::vector<std::pair<std::string, double>> held = std::move(r.locked);
    return {std::nullopt, std::move(r.model), r.constraint, std::move(held), {}};
#else
    throw nhdyn::model_error("'" + spec + "': locking joints of a DH model makes a tree, and this nhdyn was built "
                             "without tree support (urdfdom, tinyxml2)");
#endif
  }
#ifdef NHDYN_TOOL_URDF
  nhdyn::io::urdf_options o;
  o.strict = strict;
  if (robot) {
    auto r = nhdyn::io::lock_robot(nhdyn::io::load_robot_file(spec, o), locks, "--lock: ");
    // the robot file's name (its "name", else the URDF's) names the model in output and messages
    const auto& t = r.model;
    return {std::nullopt, nhdyn::tree<double>(t.bodies(), t.gravity(), r.name, t.validation_policy(), t.root_name(), t.frames()),
            r.constraint, r.locked, {}};
  }
  // a URDF is a robot without a constraint: lock_robot locks its tree and names what it held
  auto r = nhdyn::io::lock_robot({nhdyn::io::load_urdf(spec, o), std::nullopt, ""}, locks, "--lock: ");
  return {std::nullopt, std::move(r.model), std::nullopt, std::move(r.locked), {}};
#else
  (void)strict;
  throw nhdyn::model_error(spec + ": this nhdyn was built without URDF support (urdfdom, tinyxml2)");
#endif
}

std::optional<any_model> start_any_model_command(const std::vector<std::string>& args, std::string_view usage,
                                                 bool takes_terms) {
  CLI::App app;
  std::string model;
  bool strict = false;
  std::string lock, terms;
  double smooth = 0;
  app.add_option("--model", model)->required();
  app.add_flag("--strict", strict);
  app.add_option("--lock", lock);
  CLI::Option* terms_option = nullptr;
  CLI::Option* smooth_option = nullptr;
  if (takes_terms) {
    terms_option = app.add_option("--terms", terms);
    smooth_option = app.add_option("--smooth-coulomb", smooth);
  }
  if (!parse_command_line(app, args, usage)) return std::nullopt;
  nhdyn::terms t;
  if (terms_option && terms_option->count() > 0) {
    try {
      t = nhdyn::terms::parse(terms);
    } catch (const nhdyn::input_error& e) {
      throw usage_error(std::string("--") + e.what());
    }
  }
  if (smooth_option && smooth_option->count() > 0) {
    if (!t.friction) throw usage_error("--smooth-coulomb: the terms do not include friction (--terms ...,friction)");
    if (!(smooth > 0) || !std::isfinite(smooth))
      throw usage_error("--smooth-coulomb: the velocity scale must be a finite number > 0, not " + std::to_string(smooth));
    t.coulomb = nhdyn::coulomb_law::smooth(smooth);
  }
  auto any = load_any_model(model, strict, lock.empty() ? std::vector<std::pair<std::string, double>>{} : parse_locks(lock));
  any.terms = t;
  if (!t.armature) {
    if (any.tree) any.tree = nhdyn::without_armature(*any.tree);
    if (any.dh) any.dh->chain = nhdyn::without_armature(any.dh->chain);
  }
  return any;
}

nhdyn::io::model<double> load_model(const std::string& spec) {
  if (is_urdf(spec) || is_robot_file(spec))
    throw nhdyn::model_error(spec + ": URDF models and robot files work with `nhdyn model`, `id`, `fd`, `linearize` and "
                                    "`bound` so far; this command takes a preset or a JSON model");
  // A shipped model by its name (share/nhdyn/models/NAME.json) when it is neither a preset
  // nor a file.
  std::error_code ec;
  const auto dir = data_dir();
  const auto shipped = dir / "models" / (spec + ".json");
  const auto names = nhdyn::io::preset_names();
  const bool preset = std::find(names.begin(), names.end(), spec) != names.end();
  if (!preset && !std::filesystem::exists(spec, ec) && spec.find('/') == std::string::npos &&
      !dir.empty() && std::filesystem::is_regular_file(shipped, ec))
    return nhdyn::io::load<double>(shipped.string());
  return nhdyn::io::load<double>(spec);
}

std::optional<nhdyn::io::model<double>> start_model_command(const std::vector<std::string>& args,
                                                            std::string_view usage) {
  CLI::App app;
  std::string model;
  app.add_option("--model", model)->required();
  if (!parse_command_line(app, args, usage)) return std::nullopt;
  return load_model(model);
}

// ---------------------------------------------------------------------------------------

namespace {
std::string kind(const json& j) { return nhdyn::io::detail::describe(j); }

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "'" : ", '") + x + "'";
  return s;
}

double finite_number(const json& j, const std::string& what) {
  if (!j.is_number()) throw nhdyn::input_error(what + " is a " + kind(j) + ", not a number");
  const double x = j.get<double>();
  if (!std::isfinite(x)) throw nhdyn::input_error(what + " is not finite");
  return x;
}

/// Throws if an output number is NaN or Inf, naming where it is.
void check_output(const ordered_json& j, const std::string& path) {
  if (j.is_number_float()) {
    if (!std::isfinite(j.get<double>()))
      throw nhdyn::numerical_error("output " + path + " is not finite (" +
                                   (std::isnan(j.get<double>()) ? "NaN" : "Inf") +
                                   "): the input is outside what double precision can compute");
  } else if (j.is_object()) {
    for (auto it = j.begin(); it != j.end(); ++it) check_output(it.value(), path.empty() ? "'" + it.key() + "'" : path + "." + it.key());
  } else if (j.is_array()) {
    for (std::size_t i = 0; i < j.size(); ++i) check_output(j[i], path + "[" + std::to_string(i) + "]");
  }
}
}  // namespace

void line::expect_keys(const std::vector<std::string>& keys) const {
  std::vector<std::string> missing, unknown;
  for (const auto& k : keys)
    if (!j_.contains(k)) missing.push_back(k);
  for (auto it = j_.begin(); it != j_.end(); ++it)
    if (std::find(keys.begin(), keys.end(), it.key()) == keys.end()) unknown.push_back(it.key());
  if (missing.empty() && unknown.empty()) return;
  std::string msg;
  if (!unknown.empty()) msg += "unknown key(s) " + join(unknown);
  if (!missing.empty()) msg += (msg.empty() ? "" : "; ") + std::string("missing key(s) ") + join(missing);
  throw nhdyn::input_error(msg + " (expected exactly " + join(keys) + ")");
}

Eigen::VectorXd line::vector(std::string_view key, int n) const {
  const std::string k(key);
  if (!j_.contains(k)) throw nhdyn::input_error("missing key '" + k + "'");
  const json& a = j_[k];
  if (!a.is_array()) throw nhdyn::input_error("'" + k + "' is a " + kind(a) + ", not an array of numbers");
  if (n >= 0 && a.size() != static_cast<std::size_t>(n))
    throw nhdyn::input_error("'" + k + "' has " + std::to_string(a.size()) + " entries; the model needs " + std::to_string(n));
  if (a.empty()) throw nhdyn::input_error("'" + k + "' is empty");
  Eigen::VectorXd v(static_cast<Eigen::Index>(a.size()));
  for (std::size_t i = 0; i < a.size(); ++i)
    v(static_cast<Eigen::Index>(i)) = finite_number(a[i], "'" + k + "'[" + std::to_string(i) + "]");
  return v;
}

std::vector<nhdyn::wrench<double>> line_wrenches(const line& l, const wrench_maker& make) {
  std::vector<nhdyn::wrench<double>> out;
  if (!l.has("f_ext")) return out;
  const json& a = l.raw()["f_ext"];
  if (!a.is_array()) throw nhdyn::input_error("'f_ext' is a " + kind(a) + ", not a list of wrenches");
  for (std::size_t k = 0; k < a.size(); ++k) {
    const std::string w = "'f_ext'[" + std::to_string(k) + "]";
    const json& e = a[k];
    if (!e.is_object()) throw nhdyn::input_error(w + " is a " + kind(e) + ", not an object {\"body\", \"force\", …}");
    for (auto it = e.begin(); it != e.end(); ++it)
      if (it.key() != "body" && it.key() != "frame" && it.key() != "point" && it.key() != "force" && it.key() != "moment")
        throw nhdyn::input_error(w + ": unknown key '" + it.key() + "' (known: body, frame, point, force, moment)");
    if (!e.contains("body") || !e["body"].is_string()) throw nhdyn::input_error(w + ": 'body' (a body name) is missing");
    nhdyn::wrench_frame frame = nhdyn::wrench_frame::world;
    if (e.contains("frame")) {
      if (e["frame"] == "body") frame = nhdyn::wrench_frame::body;
      else if (e["frame"] != "world") throw nhdyn::input_error(w + ": 'frame' must be \"world\" or \"body\"");
    }
    const auto v3 = [&](const char* key) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      if (!e.contains(key)) return v;
      const json& x = e[key];
      const std::string what = w + "." + key;
      if (!x.is_array() || x.size() != 3) throw nhdyn::input_error(what + " is not a list of 3 numbers");
      for (int r = 0; r < 3; ++r) v(r) = finite_number(x[std::size_t(r)], what + "[" + std::to_string(r) + "]");
      return v;
    };
    out.push_back(make(e["body"].get<std::string>(), frame, v3("point"), v3("force"), v3("moment")));
  }
  return out;
}

Eigen::MatrixX2d line::intervals(std::string_view key, int n) const {
  const std::string k(key);
  if (!j_.contains(k)) throw nhdyn::input_error("missing key '" + k + "'");
  const json& a = j_[k];
  if (!a.is_array()) throw nhdyn::input_error("'" + k + "' is a " + kind(a) + ", not an array of [lo, hi] intervals");
  if (n >= 0 && a.size() != static_cast<std::size_t>(n))
    throw nhdyn::input_error("'" + k + "' has " + std::to_string(a.size()) + " intervals; the model needs " + std::to_string(n));
  Eigen::MatrixX2d m(static_cast<Eigen::Index>(a.size()), 2);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string w = "'" + k + "'[" + std::to_string(i) + "]";
    if (!a[i].is_array() || a[i].size() != 2) throw nhdyn::input_error(w + " is not an interval [lo, hi]");
    const auto r = static_cast<Eigen::Index>(i);
    m(r, 0) = finite_number(a[i][0], w + "[0]");
    m(r, 1) = finite_number(a[i][1], w + "[1]");
    if (m(r, 0) > m(r, 1)) throw nhdyn::input_error(w + " has lo > hi");
  }
  return m;
}

double line::number(std::string_view key) const {
  const std::string k(key);
  if (!j_.contains(k)) throw nhdyn::input_error("missing key '" + k + "'");
  return finite_number(j_[k], "'" + k + "'");
}

int line::integer(std::string_view key, int max) const {
  const std::string k(key);
  if (!j_.contains(k)) throw nhdyn::input_error("missing key '" + k + "'");
  const json& x = j_[k];
  if (!x.is_number_integer() || x.get<long long>() < 0 || x.get<long long>() > max)
    throw nhdyn::input_error("'" + k + "' must be an integer from 0 to " + std::to_string(max));
  return static_cast<int>(x.get<long long>());
}

int run_lines(std::istream& in, std::ostream& out, const line_handler& handle) {
  int status = 0;
  std::string text;
  for (long long n = 1; std::getline(in, text); ++n) {
    if (!text.empty() && text.back() == '\r') text.pop_back();
    const std::string where = "line " + std::to_string(n) + ": ";
    std::string reply;
    try {
      if (text.find_first_not_of(" \t") == std::string::npos)
        throw nhdyn::input_error("empty line (expected a JSON object)");
      json j = nhdyn::io::parse_strict<nhdyn::input_error>(text, "");
      if (!j.is_object()) throw nhdyn::input_error("expected a JSON object, got " + kind(j));
      const ordered_json result = handle(line(std::move(j)));
      check_output(result, "");
      reply = nhdyn::io::dump(result);
    } catch (const std::exception& e) {
      std::string msg = e.what();  // a line is one line: its JSON errors need no line number
      if (const auto p = msg.find("at line 1, column "); p != std::string::npos) msg.replace(p, 18, "at column ");
      reply = nhdyn::io::dump(ordered_json{{"error", where + msg}});
      status = 1;
    }
    out << reply << '\n' << std::flush;
  }
  return status;
}

ordered_json to_json(const Eigen::VectorXd& v) {
  ordered_json a = ordered_json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(v(i));
  return a;
}

ordered_json to_json(const Eigen::MatrixXd& m) {
  ordered_json a = ordered_json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) a.push_back(to_json(Eigen::VectorXd(m.row(r).transpose())));
  return a;
}

}  // namespace nhdyn_tool
