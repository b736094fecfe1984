#pragma once
// Checkpoints: the full state of a run — fluid velocity, rod X and D, step and simulated time —
// plus what the run driver needs to continue it exactly as if it had never stopped (the resolved
// config, the thread count, the initial observables, the self-passage bookkeeping). ibrod has no
// random state after the initial condition, so nothing else evolves. One binary file,
// little-endian:
//
//   header, 32 bytes:  char[8] magic "IBRODCKP" | u32 format version (kCheckpointVersion)
//                      | u32 byte-order mark 0x01020304 | u64 payload bytes
//                      | u32 CRC-32 (IEEE 802.3) of the payload | u32 zero
//   payload:           u64 m, m bytes of JSON (CheckpointMeta)
//                      | i64 n, n × 3 f64 X (Å) | n × 9 f64 D (per point: D¹, D², D³)
//                      | i64 N, 3 × N³ f64 fluid velocity (Å/s; u_x, u_y, u_z blocks, each in
//                        GridSpec::index order: z fastest)
//
// write_checkpoint is atomic (AtomicFile with fsync): the previous checkpoint stays intact until
// the new one is complete. read_checkpoint rejects, with a message, a file that is not a
// checkpoint, has another version or byte order, is truncated or fails its checksum.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rod/rod.hpp"
#include "sim/simulation.hpp"

namespace ibrod::io {

inline constexpr std::uint32_t kCheckpointVersion = 1;

/// Bookkeeping stored as JSON in the payload.
struct CheckpointMeta {
  std::int64_t step = 0;
  double time_s = 0;        ///< simulated time, s (state: never step × Δt; −1 if absent)
  int threads = 1;          ///< resolved OpenMP/FFTW threads of the run that wrote it
  std::string config_toml;  ///< to_toml() of the run's configuration
  std::string stop_reason = "none";     ///< "none" while running; end_time/equilibrium at the end
  sim::Observables initial;             ///< the time-series row at step 0
  bool self_passage_warning = false;    ///< |Lk − Lk(0)| exceeded 0.1 at some output step
  std::int64_t self_passage_step = -1;  ///< the first such step (−1: none)
  double max_link_drift = 0;            ///< max |Lk − Lk(0)| over the output steps so far
  double wall_s = 0;                    ///< wall time of every segment of the run up to here, s
  std::int64_t resumes = 0;             ///< how many times the run was resumed
  /// the stability tests so far (sim/stability.hpp), a JSON array of objects as summary.json
  /// lists them
  std::string stability_tests_json = "[]";
  /// time.scheme = "implicit": the step controller's next Δt (s; −1 if absent) and its run of
  /// accepted steps (sim::Simulation::implicit_state)
  double implicit_next_dt_s = -1;
  int implicit_accepted_in_a_row = 0;
  /// time.scheme = "implicit" with solvent.thermal: the state the next step's predictor filter is
  /// made at (ImplicitStepper::held_filter: X in Å, 3 per point, and D, 9 per point in the rod
  /// block's order) and the steps since K was made at a step's start; an empty X: none (made
  /// afresh at the resumed state, as in checkpoints written before it was kept)
  std::int64_t implicit_filter_steps = 0;
  std::vector<double> implicit_filter_X, implicit_filter_D;
};

struct Checkpoint {
  CheckpointMeta meta;
  rod::RodState rod;
  int grid_n = 0;
  std::vector<double> velocity;  ///< [3 N³], Å/s, u_x block, u_y block, u_z block
};

/// Writes a checkpoint of rod and the fluid velocity u (3 arrays of grid_n³ values, Å/s) to
/// `path`, atomically. Throws RunError (disk full, …); the previous file is then untouched.
void write_checkpoint(const std::filesystem::path& path, const CheckpointMeta& meta,
                      const rod::RodState& rod, int grid_n, std::array<const double*, 3> u);

/// The same, of a Simulation's state: its rod and velocity (s.velocity, 3 grid_n³ values).
void write_checkpoint(const std::filesystem::path& path, const CheckpointMeta& meta,
                      const sim::Snapshot& s, int grid_n);

/// Reads and verifies a checkpoint. Throws ConfigError naming the file and what is wrong.
Checkpoint read_checkpoint(const std::filesystem::path& path);

/// Records in meta what of a Snapshot the JSON keeps: the step, the simulated time and the
/// implicit controller (next Δt ≤ 0: the explicit scheme's −1).
void record_state(CheckpointMeta& meta, const sim::Snapshot& s);

/// The Snapshot a checkpoint holds, for Simulation::restore: its rod and velocity (moved out of
/// ck), step, time (step × dt for checkpoints from before time was state, time_s < 0) and
/// implicit controller.
sim::Snapshot snapshot_of(Checkpoint&& ck, double dt);

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320) of `bytes`, continuing from `crc`.
std::uint32_t crc32(const void* data, std::size_t bytes, std::uint32_t crc = 0);

}  // namespace ibrod::io
