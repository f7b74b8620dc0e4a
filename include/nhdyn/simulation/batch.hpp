#pragma once
/// \file simulation/batch.hpp
/// Runs many scenes in parallel on a pool of std::threads (default: all cores). Each run
/// is independent (own plant, controller, integrator, noise generator seeded by its
/// scene), so results do not depend on the number of threads or the order of completion.
///
///     auto results = nhdyn::run_batch(nhdyn::scene::expand(nhdyn::scene::load("paper-noise")), 0,
///                                     [](std::size_t i, nhdyn::run_result& r) { /* write CSV */ });
#include <algorithm>
#include <atomic>
#include <exception>
#include <thread>
#include <vector>

#include "simulation.hpp"

namespace nhdyn {

/// Simulates every spec with `threads` workers (0: std::thread::hardware_concurrency()).
/// `on_done(i, result)` runs in the worker that finished run i, concurrently with other
/// workers (write that run's files there; guard shared state such as a progress bar);
/// results come back in the order of `specs`. A
/// spec that cannot be set up (bad model) becomes a failed run with the error as reason.
/// `run(spec)` simulates one spec: `simulate` (paper5, the default) or `simulate_scene`
/// (any robot, simulation/robot_scene.hpp).
template <class OnDone, class Run = simulate_fn>
std::vector<run_result> run_batch(const std::vector<run_spec>& specs, unsigned threads, OnDone&& on_done,
                                  Run run = {}) {
  std::vector<run_result> results(specs.size());
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t i; (i = next.fetch_add(1)) < specs.size();) {
      try {
        results[i] = run(specs[i]);
      } catch (const std::exception& e) {
        results[i].name = specs[i].name;
        results[i].success = false;
        results[i].failure = std::string("setup: ") + e.what();
      }
      on_done(i, results[i]);
    }
  };
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = std::min<unsigned>(threads, unsigned(std::max<std::size_t>(1, specs.size())));
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < threads; ++k) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  return results;
}

}  // namespace nhdyn
