/// \file simulate.cpp
/// `nhdyn simulate SCENE... --out DIR`: runs scenes, studies and suites (docs/simulation.md)
/// in parallel, writes one CSV per run, DIR/summary.json, figures like the paper's
/// figs. 4–6 (gnuplot), and prints a summary table. Exit status 1 if any run fails.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <nhdyn/simulation/batch.hpp>
#include <nhdyn/simulation/scene.hpp>
#include <set>
#include <sstream>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
constexpr std::string_view usage = R"(nhdyn simulate SCENE... --out DIR [--threads N] [--no-plots]
  Runs each SCENE (a JSON file, or the name of a shipped scene: paper-circle,
  paper-factorial, paper-noise, paper = all three; shipped scenes are read from
  share/nhdyn/scenes beside the tool's bin/ folder, or from $NHDYN_SCENES_DIR) and writes
  into DIR (created):
    DIR/<run>.csv       t,q1..q5,eta1..eta4,tau1..tau4,r_x,r_y,r_z,rd_x,rd_y,rd_z,err at the
                        scene's output step, from dense output; tau is the torque applied
                        (the held value under zero-order hold), r the plant's true position,
                        err = |r_d - r|; numbers round-trip exact
    DIR/summary.json    [{name, success, max_tail_error, steps, failure, wall_time_s, cpu_time_s, peak_tau}]
    DIR/<group>-path.png, -error.png, -q.png, -tau.png   figs. 4-6 and tau(t) (gnuplot; one
                        set per scene or study, each run one colour, named in the legend)
  A study's runs go in parallel on --threads workers (default: all cores), with a progress
  bar when stderr is a terminal. Exit status: 0 all runs succeeded, 1 some run failed,
  2 bad command line.
)";

struct group {
  std::string name;
  std::vector<std::size_t> runs;
};

/// gnuplot program for one group's figures (figs. 4–6 of the paper, and τ(t)). Every run is
/// one line style throughout (colour and dash) and named in the legend by what sets it apart
/// (its name without the group's prefix, e.g. "m3_1.1-d3_0.9-a4_1-a5_1").
std::string gnuplot_program(const std::filesystem::path& dir, const group& g, const std::vector<std::string>& names) {
  std::ostringstream p;
  const std::string prefix = (dir / g.name).string();
  const auto label = [&](const std::string& run) {
    const std::string head = g.name + "-";
    return run.size() > head.size() && run.rfind(head, 0) == 0 ? run.substr(head.size()) : run;
  };
  const bool many = g.runs.size() > 1;
  p << "set terminal pngcairo size " << (many ? 1150 : 900) << ",700 noenhanced font ',10'\nset datafile separator ','\n";
  p << "files = '";
  for (auto i : g.runs) p << (dir / (names[i] + ".csv")).string() << ' ';
  p << "'\ntitles = '";
  for (auto i : g.runs) p << label(names[i]) << ' ';
  // Eight colours, then the same eight dashed, dotted…: every run of up to 40 its own line.
  p << "'\nn = words(files)\nstyle(i) = 1 + int((i - 1) / 8) % 5\nset grid\n";
  p << (many ? "set key outside right top vertical font ',8' title 'run'\n" : "set key top right\n");
  p << "set output '" << prefix << "-path.png'\nset title '" << g.name
    << ": path in the ground plane (fig. 4), seen from above; dotted: base point (q2, q1)'\n"
       "set xlabel 'y0 [m]'\nset ylabel 'z0 [m]'\nset size ratio -1\n"
       "plot word(files,1) every ::1 using 19:20 with lines dt 2 lw 2 lc rgb 'black' title 'r_d', \\\n"
       "  for [i=1:n] word(files,i) every ::1 using 16:17 with lines lw 1 lc i dt style(i) title word(titles,i), \\\n"
       "  for [i=1:n] word(files,i) every ::1 using 3:2 with lines lw 1 dt 3 lc i notitle\n"
       "set size noratio\n";
  p << "set output '" << prefix << "-error.png'\nset title '" << g.name
    << ": tracking error |r_d - r| (fig. 5)'\nset xlabel 't [s]'\nset ylabel '|r_d - r| [m]'\nset logscale y\n"
       "plot for [i=1:n] word(files,i) every ::1 using 1:21 with lines lc i dt style(i) title word(titles,i), "
       "0.01 with lines dt 2 lc rgb 'red' title 'criterion (t >= 15 s)'\n"
       "unset logscale y\n";
  // Joint coordinates and actuator torques: one panel per column. A legend does not fit
  // beside a short panel: with several runs, each keeps its line style of the figures above,
  // whose legends name them.
  const auto panels = [&](const char* file, const char* what, std::initializer_list<std::pair<int, const char*>> cols) {
    p << "set output '" << prefix << file << "'\nset multiplot layout " << cols.size() << ",1 title '" << g.name << ": "
      << what << (many ? " (line styles as in " + g.name + "-error.png)" : std::string())
      << "'\nunset title\nset xlabel ''\nset key off\n";
    int k = 0;
    for (const auto& [col, ylabel] : cols) {
      if (++k == int(cols.size())) p << "set xlabel 't [s]'\n";
      p << "set ylabel '" << ylabel << "'\nplot for [i=1:n] word(files,i) every ::1 using 1:" << col
        << " with lines lc i dt style(i) title word(titles,i)\n";
    }
    p << "unset multiplot\nset key\n";
  };
  panels("-q.png", "joint coordinates (fig. 6)",
         {{2, "q1 [m]"}, {3, "q2 [m]"}, {4, "q3 [rad]"}, {5, "q4 [rad]"}, {6, "q5 [rad]"}});
  panels("-tau.png", "actuator forces and torques applied",
         {{11, "tau1 (v) [N]"}, {12, "tau2 (omega) [N m]"}, {13, "tau3 (q4) [N m]"}, {14, "tau4 (q5) [N m]"}});
  return p.str();
}

void plot(const std::filesystem::path& dir, const std::vector<group>& groups, const std::vector<std::string>& names) {
  for (const auto& g : groups) {
    const auto script = dir / (g.name + ".gp");
    std::ofstream(script) << gnuplot_program(dir, g, names);
    const std::string cmd = "gnuplot '" + script.string() + "' 2>&1";
    if (FILE* pipe = popen(cmd.c_str(), "r")) {
      std::string out;
      char buf[256];
      while (std::fgets(buf, sizeof buf, pipe)) out += buf;
      if (pclose(pipe) != 0)
        std::cerr << "nhdyn simulate: figures for '" << g.name << "' not made (gnuplot: " << out.substr(0, 300)
                  << "); the CSVs and " << script.string() << " are there\n";
    }
  }
}

std::string fixed(double x, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << x;
  return os.str();
}

int run(const std::vector<std::string>& args) {
  CLI::App app;
  std::vector<std::string> scenes;
  std::string out;
  int threads = 0;
  bool no_plots = false;
  app.add_option("SCENE", scenes)->required();
  app.add_option("--out", out)->required();
  add_integer_option(app, "--threads", threads, 0, 4096);
  app.add_flag("--no-plots", no_plots);
  if (!parse_command_line(app, args, usage)) return 0;
  const std::filesystem::path dir = out;

  // Expand scenes into runs; a suite's members and every other SCENE are plot groups.
  std::vector<nhdyn::run_spec> specs;
  std::vector<group> groups;
  const auto add_group = [&](const nhdyn::scene::json& j, const nhdyn::scene::search_path& dirs,
                             const std::string& fallback) {
    const auto runs = nhdyn::scene::expand(j, dirs);
    group g{j.is_object() ? j.value("name", fallback) : fallback, {}};
    for (const auto& r : runs) {
      g.runs.push_back(specs.size());
      specs.push_back(r);
    }
    groups.push_back(g);
  };
  for (const auto& s : scenes) {
    const auto [j, dirs] = nhdyn::scene::open(s);  // a file, or a shipped scene's name
    if (j.contains("scenes") && j["scenes"].is_array()) {
      nhdyn::scene::expand(j, dirs);  // validates the suite itself
      for (const auto& member : j["scenes"]) {
        if (member.is_string()) {
          const auto [mj, mdirs] = nhdyn::scene::open(member.get<std::string>(), dirs);
          add_group(mj, mdirs, member.get<std::string>());
        } else {
          add_group(member, dirs, s);
        }
      }
    } else {
      add_group(j, dirs, s);
    }
  }
  std::set<std::string> seen;
  std::vector<std::string> names;
  for (const auto& s : specs) {
    if (!seen.insert(s.name).second)
      throw nhdyn::input_error("two runs are named '" + s.name + "' (their CSVs would collide)");
    if (s.name.find('/') != std::string::npos) throw nhdyn::input_error("run name '" + s.name + "' contains '/'");
    names.push_back(s.name);
  }
  std::filesystem::create_directories(dir);

  // Run, writing each CSV as its run finishes.
  const bool tty = isatty(STDERR_FILENO) != 0;
  std::mutex m;
  std::size_t done = 0;
  const auto t0 = std::chrono::steady_clock::now();
  auto results = nhdyn::run_batch(specs, unsigned(threads), [&](std::size_t i, nhdyn::run_result& r) {
    const auto tc = std::chrono::steady_clock::now();
    const double cpu0 = nhdyn::detail::thread_cpu_seconds();
    try {
      nhdyn::write_csv((dir / (r.name + ".csv")).string(), r);
    } catch (const std::exception& e) {
      r.success = false;
      r.failure = e.what();
    }
    r.wall_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
    r.cpu_time_s += nhdyn::detail::thread_cpu_seconds() - cpu0;
    r.rows.resize(0, 0);  // written; free the memory
    const std::lock_guard<std::mutex> lock(m);
    ++done;
    if (tty) {
      const int width = 30, filled = int(double(width) * double(done) / double(specs.size()));
      std::cerr << "\r[" << std::string(std::size_t(filled), '#') << std::string(std::size_t(width - filled), ' ')
                << "] " << done << "/" << specs.size() << "  " << specs[i].name << "\033[K" << std::flush;
    }
  });
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (tty) std::cerr << "\r\033[K" << std::flush;

  // summary.json and the table.
  nlohmann::ordered_json summary = nlohmann::ordered_json::array();
  for (const auto& r : results) {
    nlohmann::ordered_json e;
    e["name"] = r.name;
    e["success"] = r.success;
    e["max_tail_error"] = std::isfinite(r.max_tail_error) ? nlohmann::ordered_json(r.max_tail_error) : nullptr;
    e["steps"] = r.steps;
    e["failure"] = r.failure ? nlohmann::ordered_json(*r.failure) : nullptr;
    e["wall_time_s"] = r.wall_time_s;
    e["cpu_time_s"] = r.cpu_time_s;
    e["peak_tau"] = r.peak_tau;
    summary.push_back(e);
  }
  {
    std::ofstream f(dir / "summary.json");
    f << summary.dump(2) << '\n';
    f.flush();
    if (!f) {
      std::cerr << "nhdyn simulate: cannot write " << (dir / "summary.json").string() << '\n';
      return 1;
    }
  }

  std::size_t width = 4;
  for (const auto& r : results) width = std::max(width, r.name.size());
  std::cout << std::left << std::setw(int(width)) << "run" << "  ok   tail [mm]  peak|tau| [N]   steps  wall [ms]  cpu [ms]\n";
  int failed = 0;
  for (const auto& r : results) {
    failed += !r.success;
    std::cout << std::left << std::setw(int(width)) << r.name << "  " << (r.success ? "yes" : "NO ") << std::right
              << std::setw(11) << (std::isfinite(r.max_tail_error) ? fixed(1e3 * r.max_tail_error, 3) : "-")
              << std::setw(15) << fixed(r.peak_tau, 1) << std::setw(8) << r.steps << std::setw(11)
              << fixed(1e3 * r.wall_time_s, 1) << std::setw(10) << fixed(1e3 * r.cpu_time_s, 1) << (r.failure ? "  " + *r.failure : "") << '\n';
  }
  for (const auto& g : groups) {
    int ok = 0;
    for (auto i : g.runs) ok += results[i].success;
    std::cout << g.name << ": " << ok << "/" << g.runs.size() << " succeeded\n";
  }
  double cpu = 0;
  for (const auto& r : results) cpu += r.cpu_time_s;
  std::cout << "total: " << int(results.size()) - failed << "/" << results.size() << " succeeded in "
            << fixed(total, 2) << " s wall, " << fixed(cpu, 2) << " s cpu (" << (threads ? unsigned(threads) : std::thread::hardware_concurrency())
            << " threads); files in " << dir.string() << '\n';
  if (!no_plots) plot(dir, groups, names);
  return failed ? 1 : 0;
}
}  // namespace

command command_simulate() {
  return {"simulate", "run scenes/studies (paper-circle, paper-factorial, paper-noise): CSVs, summary, figures", usage,
          run};
}

}  // namespace nhdyn_tool
