/// \file simulate.cpp
/// `nhdyn simulate SCENE... --out DIR`: runs scenes, studies and suites (docs/simulation.md)
/// in parallel, writes one CSV per run, DIR/summary.json, figures like the paper's
/// figs. 4–6 (gnuplot), and prints a summary table. Exit status 1 if any run fails.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <nhdyn/simulation/batch.hpp>
#include <nhdyn/simulation/scene.hpp>
#ifdef NHDYN_TOOL_URDF
#include <nhdyn/simulation/robot_scene.hpp>
#endif
#ifdef NHDYN_TOOL_MPI
#include <mpi.h>
#endif
#include <set>
#include <sstream>

#include "tool.hpp"

namespace nhdyn_tool {

namespace {
constexpr std::string_view usage = R"(nhdyn simulate SCENE... --out DIR [--threads N] [--no-plots] [--html]
  Runs each SCENE (a JSON file, or the name of a shipped scene: paper-circle,
  paper-factorial, paper-noise, paper = all three, mobile-manipulator-circle,
  mobile-manipulator-monte-carlo, mecanum-sideways-circle, puma560-line,
  puma560-computed-torque; shipped scenes are read from
  share/nhdyn/scenes beside the tool's bin/ folder, or from $NHDYN_SCENES_DIR) and writes
  into DIR (created):
    DIR/<run>.csv       t,q1..q5,eta1..eta4,tau1..tau4,r_x,r_y,r_z,rd_x,rd_y,rd_z,err at the
                        scene's output step, from dense output (any other robot's scene:
                        q_<joint>..., eta_<name>..., tau_<name>... by its names); tau is the torque applied
                        (the held value under zero-order hold), r the plant's true position,
                        err = |r_d - r|; numbers round-trip exact
    DIR/summary.json    {"runs": [{name, robot, success, max_tail_error, steps, failure, wall_time_s,
                        cpu_time_s, peak_tau, seed (Monte Carlo), factors (studies), rank, host}],
                        "aggregate": {count, succeeded, success_rate, max_tail_error and
                        peak_tau percentiles (min, p5, p50, p95, max), wall_time_s, cpu_time_s}}
    DIR/<group>-path.png, -error.png, -q.png, -tau.png   figs. 4-6 and tau(t) (gnuplot; one
                        set per scene or study, each run one colour, named in the legend;
                        from 21 runs on: percentile bands per output time instead, min-max,
                        5-95 % and the median, over the runs that reached the end (a failing
                        run stops early), and 40 runs' paths, from
                        DIR/<group>-bands.csv: t, then <column>_min,_p5,_p50,_p95,_max)
    DIR/view.html       with --html: the runs in a web page (nhdyn view DIR: the robot moving,
                        its trace, the task path, tau and the error; when every run has the
                        same robot, at most 40 runs)
  A study's runs go in parallel on --threads workers (default: all cores), with a progress
  bar and an ETA when stderr is a terminal. Under MPI (mpirun -n N nhdyn simulate ...) the
  runs are handed out one at a time to N processes on any machines (rank 0 runs them too),
  each process writes the CSVs of its runs, and rank 0 gathers summary.json (each run's
  "rank" and "host" say where it ran; the results are those of one process, bit for bit). Exit status: 0 all runs succeeded, 1 some run failed,
  2 bad command line.
)";

struct group {
  std::string name;
  std::vector<std::size_t> runs;
};

/// The 1-based (gnuplot) number of the column called `name`; 0 if there is none.
int column_of(const std::vector<std::string>& columns, const std::string& name) {
  for (std::size_t j = 0; j < columns.size(); ++j)
    if (columns[j] == name) return int(j) + 1;
  return 0;
}

/// A figure of one panel per column whose name starts with `prefix_of` (three per row from
/// five panels on): DIR/<group><file>, titled `title`; each panel labelled with the column's
/// name (without the prefix when `strip`) and drawn by `panel(column)`.
template <class Panel>
void panel_grid(std::ostringstream& p, const std::string& prefix, const char* file, const std::string& title,
                const std::vector<std::string>& columns, const std::string& prefix_of, bool strip, const Panel& panel) {
  std::vector<int> cs;
  for (std::size_t j = 1; j < columns.size(); ++j)
    if (columns[j].rfind(prefix_of, 0) == 0) cs.push_back(int(j) + 1);
  const int per_row = cs.size() > 4 ? 3 : 1, rows = (int(cs.size()) + per_row - 1) / per_row;
  p << "set terminal pngcairo size " << (per_row > 1 ? 1400 : 900) << "," << std::max(400, 170 * rows)
    << " noenhanced font ',9'\nset output '" << prefix << file << "'\nset multiplot layout " << rows << "," << per_row
    << " title '" << title << "'\nunset title\nset xlabel ''\nset key off\n";
  for (int c : cs) {
    p << "set ylabel '" << columns[std::size_t(c - 1)].substr(strip ? prefix_of.size() : 0) << "'\n";
    panel(c);
  }
  p << "unset multiplot\nset key\n";
}

/// gnuplot program for one group's figures (figs. 4–6 of the paper, and τ(t)). Every run is
/// one line style throughout (colour and dash) and named in the legend by what sets it apart
/// (its name without the group's prefix, e.g. "m3_1.1-d3_0.9-a4_1-a5_1"). `columns`: the
/// group's CSV columns; paper5's get the paper's figures, any other robot's the same four
/// figures from its column names (path seen from above: r_x, r_y).
std::string gnuplot_program(const std::filesystem::path& dir, const group& g, const std::vector<std::string>& names,
                            const std::vector<std::string>& columns) {
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
  const bool paper5 = columns == nhdyn::run_columns();
  const auto col = [&](const std::string& name) { return column_of(columns, name); };
  if (!paper5) {  // any robot: the same figures, from the column names
    // a planar base: its trace on the floor too (the root link's origin, grey)
    const bool base = col("q_base_x") > 0 && col("q_base_y") > 0;
    p << "set output '" << prefix << "-path.png'\nset title '" << g.name << ": task point" << (base ? " and base" : "")
      << " seen from above'\n"
      << "set xlabel 'x [m]'\nset ylabel 'y [m]'\nset size ratio -1\n"
      << "plot word(files,1) every ::1 using " << col("rd_x") << ":" << col("rd_y")
      << " with lines dt 2 lw 2 lc rgb 'black' title 'r_d', \\\n  for [i=1:n] word(files,i) every ::1 using " << col("r_x")
      << ":" << col("r_y") << " with lines lw 1 lc i dt style(i) title word(titles,i)";
    if (base)
      p << ", \\\n  for [i=1:n] word(files,i) every ::1 using " << col("q_base_x") << ":" << col("q_base_y")
        << " with lines lw 2 lc rgb 'grey60' dt style(i) title (i == 1 ? 'base' : '')";
    p << "\nset size noratio\n";
    p << "set output '" << prefix << "-error.png'\nset title '" << g.name
      << ": tracking error |r_d - r|'\nset xlabel 't [s]'\nset ylabel '|r_d - r| [m]'\nset logscale y\n"
      << "plot for [i=1:n] word(files,i) every ::1 using 1:" << col("err") << " with lines lc i dt style(i) title word(titles,i)\n"
      << "unset logscale y\n";
    const auto lines = [&](int c) { p << "plot for [i=1:n] word(files,i) every ::1 using 1:" << c << " with lines lc i dt style(i)\n"; };
    panel_grid(p, prefix, "-q.png", g.name + ": joint coordinates q (t)", columns, "q_", true, lines);
    panel_grid(p, prefix, "-tau.png", g.name + ": actuator forces and torques applied (t)", columns, "tau_", true, lines);
    return p.str();
  }
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

/// Groups of this many runs or more get percentile bands instead of one line per run.
constexpr std::size_t band_from = 21;

/// Columns [c0, c1) of a CSV written by write_csv (header skipped), row after row in one
/// buffer; `rows` gets the number of rows. Empty if the file is not there or not such a CSV.
std::vector<double> read_columns(const std::filesystem::path& file, std::size_t c0, std::size_t c1, std::size_t& rows) {
  std::vector<double> out;
  rows = 0;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return out;
  while (std::getline(in, line)) {
    const char* c = line.data();
    const char* const end = line.data() + line.size();
    std::size_t j = 0;
    for (; c < end; ++j) {
      double x = 0;
      const auto [next, ec] = std::from_chars(c, end, x);
      if (ec != std::errc() || (next < end && *next != ',')) return {};
      if (j >= c0 && j < c1) out.push_back(x);
      c = next < end ? next + 1 : next;
    }
    if (j < c1) return {};
    ++rows;
  }
  return out;
}

/// DIR/<group>-bands.csv: per output time, the min, p5, p50, p95 and max of every column over
/// the group's runs with the most output rows — those that reached the end (a failing run
/// stops early and is left out). Read back from the runs' CSVs (under MPI each was written
/// where it ran, so this needs them in one folder), a block of columns at a time (≤ 2^25
/// numbers in memory: 1000 runs of 2001 rows take 63 columns in 4 passes). Returns how many
/// runs it used; 0 when no run had rows.
std::size_t write_bands(const std::filesystem::path& dir, const group& g, const std::vector<std::string>& names,
                        const std::vector<std::string>& columns) {
  std::vector<std::size_t> rows_of(g.runs.size());
  for (std::size_t r = 0; r < g.runs.size(); ++r) read_columns(dir / (names[g.runs[r]] + ".csv"), 0, 1, rows_of[r]);
  const std::size_t longest = rows_of.empty() ? 0 : *std::max_element(rows_of.begin(), rows_of.end());
  std::vector<std::size_t> used;
  for (std::size_t r = 0; r < g.runs.size(); ++r)
    if (longest > 0 && rows_of[r] == longest) used.push_back(g.runs[r]);
  if (used.empty()) return 0;
  const std::size_t ncol = columns.size();
  const std::size_t block = std::max<std::size_t>(1, (std::size_t(1) << 25) / (used.size() * longest));
  // bands[k][5 (j − 1) + q]: row k, column j ≥ 1, statistic q (min, p5, p50, p95, max)
  std::vector<std::vector<double>> bands(longest, std::vector<double>(5 * (ncol - 1)));
  std::vector<double> t(longest);
  std::vector<double> v;
  for (std::size_t c0 = 0; c0 < ncol; c0 += block) {
    const std::size_t c1 = std::min(ncol, c0 + block), w = c1 - c0;
    std::vector<std::vector<double>> data;  // per run: longest × w
    for (auto i : used) {
      std::size_t rows = 0;
      data.push_back(read_columns(dir / (names[i] + ".csv"), c0, c1, rows));
      if (rows != longest) return 0;  // changed under us
    }
    for (std::size_t k = 0; k < longest; ++k)
      for (std::size_t j = c0; j < c1; ++j) {
        if (j == 0) {
          t[k] = data[0][k * w];
          continue;
        }
        v.clear();
        for (const auto& d : data)
          if (std::isfinite(d[k * w + (j - c0)])) v.push_back(d[k * w + (j - c0)]);
        double* b = &bands[k][5 * (j - 1)];
        if (v.empty()) {
          std::fill(b, b + 5, NAN);
          continue;
        }
        std::sort(v.begin(), v.end());
        const auto at = [&](double f) {  // linear interpolation between order statistics (as summary.json)
          const double x = f * double(v.size() - 1);
          const std::size_t i = std::size_t(x);
          return i + 1 < v.size() ? v[i] + (x - double(i)) * (v[i + 1] - v[i]) : v[i];
        };
        b[0] = v.front(), b[1] = at(0.05), b[2] = at(0.5), b[3] = at(0.95), b[4] = v.back();
      }
  }
  std::ofstream out(dir / (g.name + "-bands.csv"));
  out << "t";
  for (std::size_t j = 1; j < ncol; ++j)
    for (const char* q : {"_min", "_p5", "_p50", "_p95", "_max"}) out << ',' << columns[j] << q;
  out << '\n' << std::setprecision(9);
  for (std::size_t k = 0; k < longest; ++k) {
    out << t[k];
    for (double x : bands[k]) out << ',' << x;
    out << '\n';
  }
  return used.size();
}

/// gnuplot program for a group of many runs: the same four figures, each column as bands
/// (min-max, 5-95 %, median) over the runs; the path figure shows r_d and 40 runs' paths.
std::string gnuplot_bands(const std::filesystem::path& dir, const group& g, const std::vector<std::string>& names,
                          const std::vector<std::string>& columns, std::size_t used) {
  std::ostringstream p;
  const std::string prefix = (dir / g.name).string(), bands = prefix + "-bands.csv";
  const bool paper5 = columns == nhdyn::run_columns();
  const auto col = [&](const std::string& name) { return column_of(columns, name); };
  // column c (1-based in a run's CSV, c ≥ 2) → its five columns in bands.csv (q: 0 min … 4 max)
  const auto band = [&](int c, int q) { return 2 + 5 * (c - 2) + q; };
  const std::string of = std::to_string(used) + " of " + std::to_string(g.runs.size()) + " runs";
  const auto plot_band = [&](int c, bool key) {
    p << "plot '" << bands << "' every ::1 using 1:" << band(c, 0) << ":" << band(c, 4)
      << " with filledcurves lc rgb '#deebf7' " << (key ? "title 'min-max'" : "notitle") << ", \\\n  '' every ::1 using 1:"
      << band(c, 1) << ":" << band(c, 3) << " with filledcurves lc rgb '#9ecae1' " << (key ? "title '5-95 %'" : "notitle")
      << ", \\\n  '' every ::1 using 1:" << band(c, 2) << " with lines lw 2 lc rgb '#08519c' "
      << (key ? "title 'median'" : "notitle") << "\n";
  };
  p << "set terminal pngcairo size 900,700 noenhanced font ',10'\nset datafile separator ','\nset grid\nset key top right\n";
  // the path: r_d and the paths of (up to) 40 runs, thin
  const std::size_t shown = std::min<std::size_t>(40, g.runs.size());
  const int rx = col(paper5 ? "r_y" : "r_x"), ry = col(paper5 ? "r_z" : "r_y");
  const int dx = col(paper5 ? "rd_y" : "rd_x"), dy = col(paper5 ? "rd_z" : "rd_y");
  p << "files = '";
  for (std::size_t k = 0; k < shown; ++k) p << (dir / (names[g.runs[k]] + ".csv")).string() << ' ';
  p << "'\nn = words(files)\nset output '" << prefix << "-path.png'\nset title '" << g.name
    << ": task point seen from above (" << shown << " of " << g.runs.size() << " runs)'\nset xlabel '"
    << (paper5 ? "y0" : "x") << " [m]'\nset ylabel '" << (paper5 ? "z0" : "y") << " [m]'\nset size ratio -1\n"
    << "plot for [i=1:n] word(files,i) every ::1 using " << rx << ":" << ry
    << " with lines lw 1 lc rgb '#80808080' notitle, \\\n  word(files,1) every ::1 using " << dx << ":" << dy
    << " with lines dt 2 lw 2 lc rgb 'black' title 'r_d'\nset size noratio\n";
  p << "set output '" << prefix << "-error.png'\nset title '" << g.name << ": tracking error |r_d - r| over " << of
    << "'\nset xlabel 't [s]'\nset ylabel '|r_d - r| [m]'\nset logscale y\n";
  plot_band(col("err"), true);
  p << "unset logscale y\n";
  const auto bands_of = [&](int c) { plot_band(c, false); };
  const std::string how = ", " + of + " (median, 5-95 %, min-max)";
  panel_grid(p, prefix, "-q.png", g.name + ": joint coordinates q (t)" + how, columns, paper5 ? "q" : "q_", !paper5, bands_of);
  panel_grid(p, prefix, "-tau.png", g.name + ": actuator forces and torques applied (t)" + how, columns, paper5 ? "tau" : "tau_",
             !paper5, bands_of);
  return p.str();
}

void plot(const std::filesystem::path& dir, const std::vector<group>& groups, const std::vector<std::string>& names,
          const std::vector<nhdyn::run_result>& results) {
  for (const auto& g : groups) {
    if (g.runs.empty()) continue;
    const auto& columns = results[g.runs.front()].columns;
    bool same = !columns.empty();
    for (auto i : g.runs) same = same && results[i].columns == columns;
    if (!same) {
      std::cerr << "nhdyn simulate: figures for '" << g.name << "' not made (its runs have different columns or failed to start)\n";
      continue;
    }
    const auto script = dir / (g.name + ".gp");
    if (g.runs.size() >= band_from) {
      const std::size_t used = write_bands(dir, g, names, columns);
      if (used == 0) {
        std::cerr << "nhdyn simulate: figures for '" << g.name << "' not made (no run's CSV in " << dir.string() << ")\n";
        continue;
      }
      std::ofstream(script) << gnuplot_bands(dir, g, names, columns, used);
    } else {
      std::ofstream(script) << gnuplot_program(dir, g, names, columns);
    }
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

/// MPI when the tool runs under mpirun (its environment says so), else one process of rank 0.
struct mpi_session {
  int rank = 0, size = 1;
  bool active = false;
  mpi_session() {
    const char* world = std::getenv("OMPI_COMM_WORLD_SIZE");
    if (!world) world = std::getenv("PMI_SIZE");
#ifdef NHDYN_TOOL_MPI
    if (world || std::getenv("PMIX_RANK")) {
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);  // MPI calls: main thread only
      active = true;
      MPI_Comm_rank(MPI_COMM_WORLD, &rank);
      MPI_Comm_size(MPI_COMM_WORLD, &size);
      if (provided < MPI_THREAD_FUNNELED) {
        if (rank == 0) std::cerr << "nhdyn simulate: the MPI library does not support threads (MPI_THREAD_FUNNELED)\n";
        MPI_Abort(MPI_COMM_WORLD, 1);
      }
    }
#else
    if (world && std::atoi(world) > 1)  // every process would run every run into the same DIR
      throw nhdyn::input_error("this nhdyn was built without MPI (libopenmpi-dev) but runs under mpirun with " +
                               std::string(world) + " processes; run it without mpirun, or rebuild with MPI");
#endif
  }
  ~mpi_session() {
#ifdef NHDYN_TOOL_MPI
    if (active) MPI_Finalize();
#endif
  }
  mpi_session(const mpi_session&) = delete;
  mpi_session& operator=(const mpi_session&) = delete;
};

/// A finished run's summary fields (not its rows: the CSV is written where it ran) as JSON
/// text, and back: doubles print in their shortest round-trip form, so they travel exactly.
std::string pack_result(std::size_t i, const nhdyn::run_result& r) {
  nlohmann::ordered_json e;
  e["i"] = i;
  e["name"] = r.name;
  e["success"] = r.success;
  e["failure"] = r.failure ? nlohmann::ordered_json(*r.failure) : nullptr;
  e["max_tail_error"] = std::isfinite(r.max_tail_error) ? nlohmann::ordered_json(r.max_tail_error) : nullptr;
  e["peak_tau"] = r.peak_tau;
  e["steps"] = r.steps;
  e["wall_time_s"] = r.wall_time_s;
  e["cpu_time_s"] = r.cpu_time_s;
  e["columns"] = r.columns;
  return e.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // a non-UTF-8 reason cannot stop it
}
std::size_t unpack_result(const std::string& text, nhdyn::run_result& r) {
  const auto e = nlohmann::json::parse(text);
  r.name = e["name"].get<std::string>();
  r.success = e["success"].get<bool>();
  if (!e["failure"].is_null()) r.failure = e["failure"].get<std::string>();
  r.max_tail_error = e["max_tail_error"].is_null() ? NAN : e["max_tail_error"].get<double>();
  r.peak_tau = e["peak_tau"].get<double>();
  r.steps = e["steps"].get<long>();
  r.wall_time_s = e["wall_time_s"].get<double>();
  r.cpu_time_s = e["cpu_time_s"].get<double>();
  r.columns = e["columns"].get<std::vector<std::string>>();
  return e["i"].get<std::size_t>();
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
  bool html = false;
  app.add_flag("--html", html);
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

  // Run, writing each CSV as its run finishes (in the process that ran it).
  const mpi_session mpi;
  const bool tty = mpi.rank == 0 && isatty(STDERR_FILENO) != 0;
  std::mutex m;
  std::size_t done = 0;
  const auto t0 = std::chrono::steady_clock::now();
#ifdef NHDYN_TOOL_URDF
  const auto runner = nhdyn::simulate_scene;  // paper5 and any other model
#else
  const auto runner = nhdyn::simulate;  // paper5 only (robot files need URDF support)
#endif
  const auto finish = [&](nhdyn::run_result& r) {  // in the worker that ran it
    const auto tc = std::chrono::steady_clock::now();
    const double cpu0 = nhdyn::detail::thread_cpu_seconds();
    if (r.columns.empty()) return;  // it failed before it started (a setup error): no rows, no CSV
    try {
      nhdyn::write_csv((dir / (r.name + ".csv")).string(), r);
    } catch (const std::exception& e) {
      r.success = false;
      r.failure = e.what();
    }
    r.wall_time_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
    r.cpu_time_s += nhdyn::detail::thread_cpu_seconds() - cpu0;
    r.rows.resize(0, 0);  // written; free the memory
  };
  // The bar counts finished runs and, within the runs this process is running, their
  // simulated time (run_options::progress), so a long single run moves it too.
  std::vector<std::atomic<double>> partial(specs.size());  // fraction of run i simulated
  std::vector<char> finished(specs.size(), 0);
  std::string last_name;
  if (tty)
    for (std::size_t i = 0; i < specs.size(); ++i)
      specs[i].progress = [&partial, i, d = specs[i].duration](double t) {
        partial[i].store(std::min(1.0, t / d), std::memory_order_relaxed);
      };
  const auto draw = [&] {  // rank 0, under m
    double sum = 0;
    for (std::size_t i = 0; i < specs.size(); ++i) sum += finished[i] ? 1.0 : partial[i].load(std::memory_order_relaxed);
    const double f = sum / double(specs.size());
    const int width = 30, filled = int(double(width) * f);
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::cerr << "\r[" << std::string(std::size_t(filled), '#') << std::string(std::size_t(width - filled), ' ') << "] "
              << done << "/" << specs.size() << "  " << fixed(elapsed, 0) << " s, ETA "
              << (f > 0 ? fixed(elapsed * (1 - f) / f, 0) + " s" : std::string("?")) << "  " << last_name << "\033[K"
              << std::flush;
  };
  const auto progress = [&](std::size_t i) {  // rank 0, under m
    ++done;
    finished[i] = 1;
    last_name = specs[i].name;
    if (tty) draw();
  };
  std::atomic<bool> all_done{false};
  std::thread ticker;  // redraws the bar between finished runs
  struct stop_ticker {  // joined on every way out (an exception included)
    std::atomic<bool>& done;
    std::thread& t;
    ~stop_ticker() {
      done = true;
      if (t.joinable()) t.join();
    }
  } stop{all_done, ticker};
  if (tty)
    ticker = std::thread([&] {
      while (!all_done.load()) {
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
        const std::lock_guard<std::mutex> lock(m);
        if (!all_done.load()) draw();
      }
    });
  std::vector<nhdyn::run_result> results;
  std::vector<int> ranks(specs.size(), 0);
  if (mpi.size == 1) {
    results = nhdyn::run_batch(specs, unsigned(threads), [&](std::size_t i, nhdyn::run_result& r) {
      finish(r);
      const std::lock_guard<std::mutex> lock(m);
      progress(i);
    }, runner);
  }
#ifdef NHDYN_TOOL_MPI
  else {  // runs handed out one at a time by rank 0 (which also runs them), results gathered there
    const auto run_one = [&](std::size_t i) {
      nhdyn::run_result r;
      try {
        r = runner(specs[i]);
      } catch (const std::exception& e) {
        r.name = specs[i].name;
        r.success = false;
        r.failure = std::string("setup: ") + e.what();
      }
      finish(r);
      return r;
    };
    constexpr int tag_request = 1, tag_index = 2;
    if (mpi.rank == 0) {
      results.resize(specs.size());
      std::atomic<std::size_t> next{0};
      std::thread local([&] {
        for (std::size_t i; (i = next.fetch_add(1)) < specs.size();) {
          nhdyn::run_result r = run_one(i);
          const std::lock_guard<std::mutex> lock(m);
          results[i] = std::move(r);
          progress(i);
        }
      });
      for (int workers = mpi.size - 1; workers > 0;) {
        int flag = 0;
        MPI_Status st;
        MPI_Iprobe(MPI_ANY_SOURCE, tag_request, MPI_COMM_WORLD, &flag, &st);
        if (!flag) {  // poll gently: a blocking probe would spin on the local worker's core
          std::this_thread::sleep_for(std::chrono::microseconds(500));
          continue;
        }
        int len = 0;
        MPI_Get_count(&st, MPI_CHAR, &len);
        std::string msg(std::size_t(len), '\0');
        MPI_Recv(msg.data(), len, MPI_CHAR, st.MPI_SOURCE, tag_request, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (!msg.empty()) {
          nhdyn::run_result r;
          const std::size_t i = unpack_result(msg, r);
          const std::lock_guard<std::mutex> lock(m);
          results[i] = std::move(r);
          ranks[i] = st.MPI_SOURCE;
          progress(i);
        }
        const std::size_t i = next.fetch_add(1);
        long long index = i < specs.size() ? static_cast<long long>(i) : -1;
        if (index < 0) --workers;
        MPI_Send(&index, 1, MPI_LONG_LONG, st.MPI_SOURCE, tag_index, MPI_COMM_WORLD);
      }
      local.join();
    } else {
      std::string msg;
      for (;;) {
        MPI_Send(msg.data(), int(msg.size()), MPI_CHAR, 0, tag_request, MPI_COMM_WORLD);
        long long index = -1;
        MPI_Recv(&index, 1, MPI_LONG_LONG, 0, tag_index, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (index < 0) break;
        try {
          msg = pack_result(std::size_t(index), run_one(std::size_t(index)));
        } catch (const std::exception& e) {  // never leave rank 0 waiting: report the run as failed
          nhdyn::run_result r;
          r.name = specs[std::size_t(index)].name;
          r.failure = std::string("rank ") + std::to_string(mpi.rank) + ": " + e.what();
          msg = pack_result(std::size_t(index), r);
        }
      }
      char host_buf[256] = {};
      if (gethostname(host_buf, sizeof host_buf - 1) != 0) std::snprintf(host_buf, sizeof host_buf, "unknown");
      MPI_Send(host_buf, int(std::strlen(host_buf)) + 1, MPI_CHAR, 0, 3, MPI_COMM_WORLD);
      return 0;  // rank 0 reports
    }
  }
#endif
  all_done = true;
  if (ticker.joinable()) ticker.join();
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (tty) std::cerr << "\r\033[K" << std::flush;

  // summary.json and the table.
  char host_buf[256] = {};
  const std::string host = gethostname(host_buf, sizeof host_buf - 1) == 0 ? host_buf : "unknown";
  std::vector<std::string> hosts(std::size_t(mpi.size), host);
#ifdef NHDYN_TOOL_MPI
  if (mpi.size > 1)
    for (int k = 1; k < mpi.size; ++k) {  // each worker sent its host name after its last run
      char buf[256] = {};
      MPI_Recv(buf, 255, MPI_CHAR, k, 3, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      hosts[std::size_t(k)] = buf;
    }
#endif
  nlohmann::ordered_json runs = nlohmann::ordered_json::array();
  std::vector<double> tails, peaks;
  int succeeded = 0;
  double cpu_sum = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const auto& r = results[i];
    nlohmann::ordered_json e;
    e["name"] = r.name;
    {  // the robot as `nhdyn view` finds it again: a preset's name, or the file's absolute path
      std::error_code ec;
      const auto p = std::filesystem::absolute(specs[i].robot, ec);
      e["robot"] = !ec && std::filesystem::is_regular_file(p, ec) ? p.string() : specs[i].robot;
      if (!specs[i].locked.empty()) {  // the scene's "locked": the runs' q has the kept joints
        nlohmann::ordered_json l = nlohmann::ordered_json::object();
        for (const auto& [name, x] : specs[i].locked) l[name] = x;
        e["locked"] = l;
      }
    }
    e["success"] = r.success;
    e["max_tail_error"] = std::isfinite(r.max_tail_error) ? nlohmann::ordered_json(r.max_tail_error) : nullptr;
    e["steps"] = r.steps;
    e["failure"] = r.failure ? nlohmann::ordered_json(*r.failure) : nullptr;
    e["wall_time_s"] = r.wall_time_s;
    e["cpu_time_s"] = r.cpu_time_s;
    e["peak_tau"] = r.peak_tau;
    if (specs[i].run_seed) e["seed"] = *specs[i].run_seed;
    if (!specs[i].factors.empty()) e["factors"] = nlohmann::ordered_json::parse(specs[i].factors);
    e["rank"] = ranks[i];  // the process that ran it (0: no MPI)
    e["host"] = hosts[std::size_t(ranks[i])];
    runs.push_back(e);
    succeeded += r.success;
    cpu_sum += r.cpu_time_s;
    if (std::isfinite(r.max_tail_error)) tails.push_back(r.max_tail_error);
    if (!r.columns.empty()) peaks.push_back(r.peak_tau);  // runs that started
  }
  const auto percentiles = [](std::vector<double> v) {
    nlohmann::ordered_json p;
    if (v.empty()) return nlohmann::ordered_json(nullptr);
    std::sort(v.begin(), v.end());
    const auto at = [&](double f) {  // linear interpolation between order statistics
      const double x = f * double(v.size() - 1);
      const std::size_t k = std::size_t(x);
      return k + 1 < v.size() ? v[k] + (x - double(k)) * (v[k + 1] - v[k]) : v[k];
    };
    p["min"] = v.front();
    p["p5"] = at(0.05);
    p["p50"] = at(0.5);
    p["p95"] = at(0.95);
    p["max"] = v.back();
    return p;
  };
  nlohmann::ordered_json aggregate;
  aggregate["count"] = results.size();
  aggregate["succeeded"] = succeeded;
  aggregate["success_rate"] = results.empty() ? 0.0 : double(succeeded) / double(results.size());
  aggregate["max_tail_error"] = percentiles(tails);
  aggregate["peak_tau"] = percentiles(peaks);
  aggregate["wall_time_s"] = total;
  aggregate["cpu_time_s"] = cpu_sum;
  aggregate["processes"] = mpi.size;
  nlohmann::ordered_json summary;
  summary["runs"] = runs;
  summary["aggregate"] = aggregate;
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
            << fixed(total, 2) << " s wall, " << fixed(cpu, 2) << " s cpu ("
            << (mpi.size > 1 ? std::to_string(mpi.size) + " MPI processes"
                             : std::to_string(threads ? unsigned(threads) : std::thread::hardware_concurrency()) + " threads")
            << "); files in " << dir.string() << '\n';
  if (!no_plots) plot(dir, groups, names, results);
  if (html) {
    try {
      std::cout << "page: " << write_view_page(dir, "", "", {}).string() << '\n';
    } catch (const std::exception& e) {  // the runs are written; the page is the extra
      std::cerr << "nhdyn simulate: --html: " << e.what() << '\n';
      return 1;
    }
  }
  return failed ? 1 : 0;
}
}  // namespace

command command_simulate() {
  return {"simulate", "run scenes/studies (paper-circle, paper-factorial, paper-noise): CSVs, summary, figures", usage,
          run};
}

}  // namespace nhdyn_tool
