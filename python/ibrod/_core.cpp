// The compiled part of the Python module `ibrod` (docs/python.md): the configuration
// (config::Config, the same schema and messages as TOML and --set) and a simulation
// (driver::Run step by step: the same loop, files and checks as `ibrod run`). The time loop runs
// in C++ with the GIL released; Ctrl-C is seen every 0.1 s of wall time and stops the run as
// SIGINT stops `ibrod run` (checkpoint and final files when writing a directory), then raises
// KeyboardInterrupt; a SIGTERM during run() stops it the same way, then raises SystemExit(143).
// ConfigError and RunError become ibrod.ConfigError (a ValueError) and ibrod.RunError (a
// RuntimeError) with the CLI's messages.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/config.hpp"
#include "core/error.hpp"
#include "core/units.hpp"
#include "driver/run.hpp"
#include "io/csv.hpp"
#include "io/observables.hpp"
#include "rod/rod_set.hpp"

namespace py = pybind11;
using namespace ibrod;

namespace {

std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// SIGTERM while run() advances a simulation: a batch system's way to end a job. Python leaves it
// at its default (the process dies at once: no checkpoint, no final files), so while the loop
// runs a handler of ours sets a flag the loop reads before each step, and the segment stops as
// on Ctrl-C; run() then raises SystemExit(143). A handler the program set itself
// (signal.signal) is left alone: PyErr_CheckSignals runs it.
volatile std::sig_atomic_t g_sigterm = 0;
void on_sigterm(int) { g_sigterm = 1; }

struct SigtermGuard {
  bool installed = false;
  struct sigaction old {};
  SigtermGuard() {
    if (sigaction(SIGTERM, nullptr, &old) != 0 || old.sa_handler != SIG_DFL) return;
    struct sigaction sa {};
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = on_sigterm;
    sa.sa_flags = SA_RESTART;
    g_sigterm = 0;
    installed = sigaction(SIGTERM, &sa, nullptr) == 0;
  }
  ~SigtermGuard() {
    if (installed) sigaction(SIGTERM, &old, nullptr);
  }
  bool pending() const { return installed && g_sigterm != 0; }
};

// One trajectory driven from Python: a driver::Run prepared at construction.
class PySimulation {
 public:
  PySimulation(const config::Config& c, std::optional<std::string> output, bool overwrite,
               bool progress) {
    driver::RunOptions o;
    o.output_dir = output.value_or("");
    o.write_files = output.has_value();
    if (output && output->empty())
      throw ConfigError("Simulation: output = '' names no directory (None: write no files)");
    o.overwrite = overwrite;
    o.handle_signals = false;  // Python keeps its SIGINT handler; run() polls it
    o.log = progress ? stdout : nullptr;
    o.tty = 0;
    o.keep_rows = true;
    run_ = std::make_unique<driver::Run>(c, o);
    run_->prepare();
  }

  // The state while run() advances it (the GIL released) belongs to the loop: another thread
  // that asks for it is refused rather than handed a state in the middle of a step.
  sim::Simulation& s() {
    if (running_)
      throw std::runtime_error("Simulation: run() is advancing this simulation in another thread");
    return run_->simulation();
  }

  // An end time as config.toml shows it: 12 significant digits, so that 200 steps of 0.1 ns
  // read 0.02, not 0.020000000000000004 (the change, ≤ 1e-12 relative, is far below the half
  // step within which a segment ends; the segment still ends after exactly `steps` steps).
  static double decimal_us(double t) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.12g", t);
    return std::strtod(buf, nullptr);
  }

  py::dict run(std::optional<std::int64_t> steps, std::optional<double> until_us) {
    sim::Simulation& sm = s();
    if (steps && until_us) throw std::invalid_argument("run: give steps or until_us, not both");
    std::int64_t max_steps = -1;
    if (steps) {
      if (*steps <= 0)
        throw std::invalid_argument("run: steps = " + std::to_string(*steps) +
                                    "; a positive number of steps is allowed");
      max_steps = *steps;
      // the segment ends after `steps` steps of Δt (implicit: steps of at most Δt)
      run_->set_end_time(decimal_us((sm.time() + double(*steps) * sm.dt()) / 1e-6));
    } else if (until_us) {
      if (!(*until_us * 1e-6 > sm.time() + 0.5 * sm.dt()))
        throw std::invalid_argument(
            "run: until_us = " + std::to_string(*until_us) + " is not after the current time " +
            std::to_string(sm.time() / 1e-6) + " µs by at least half a step");
      run_->set_end_time(*until_us);
    } else if (sm.at_end()) {
      throw std::invalid_argument("run: the simulation is at its end time (time.t_end_us = " +
                                  std::to_string(run_->config().time_t_end_us) +
                                  "); give steps or until_us");
    }
    driver::RunResult r;
    {
      struct Running {  // running_ for the loop's duration, exceptions included
        std::atomic<bool>& flag;
        explicit Running(std::atomic<bool>& f) : flag(f) { flag = true; }
        ~Running() { flag = false; }
      } running(running_);
      const SigtermGuard sigterm;
      py::gil_scoped_release release;
      using Clock = std::chrono::steady_clock;
      auto last = Clock::now();
      r = run_->advance(max_steps, [&last, &sigterm]() -> int {
        if (sigterm.pending()) return SIGTERM;
        const auto now = Clock::now();
        if (now - last < std::chrono::milliseconds(100)) return 0;
        last = now;
        py::gil_scoped_acquire acquire;
        return PyErr_CheckSignals() != 0 ? SIGINT : 0;
      });
    }
    if (r.signal == SIGTERM) {
      // stopped as `ibrod run` stops on SIGTERM (checkpoint, final files): exit status 143
      PyErr_SetObject(PyExc_SystemExit, py::int_(128 + SIGTERM).ptr());
      throw py::error_already_set();
    }
    if (r.signal) throw py::error_already_set();  // KeyboardInterrupt (set by PyErr_CheckSignals)
    py::dict d;
    d["steps"] = r.steps;
    d["time_us"] = r.time_us;
    d["stop_reason"] = sim::to_string(r.reason);
    d["ms_per_step"] = r.ms_per_step;
    d["wall_s"] = r.wall_s;
    return d;
  }

  py::array_t<double> positions() {
    const rod::RodState& st = s().rod();
    py::array_t<double> a({py::ssize_t(st.size()), py::ssize_t(3)});
    double* p = a.mutable_data();
    for (int k = 0; k < st.size(); ++k)
      for (int c = 0; c < 3; ++c) p[3 * k + c] = st.X[k][c];
    return a;
  }

  py::array_t<double> triads() {
    const rod::RodState& st = s().rod();
    py::array_t<double> a({py::ssize_t(st.size()), py::ssize_t(3), py::ssize_t(3)});
    double* p = a.mutable_data();
    // row i of a[k] is the column D^(i+1) of D_k
    for (int k = 0; k < st.size(); ++k)
      for (int i = 0; i < 3; ++i)
        for (int c = 0; c < 3; ++c) p[9 * k + 3 * i + c] = st.D[k](c, i);
    return a;
  }

  void set_state(const py::object& X_in, const py::object& D_in) {
    const int n = config::point_count(run_->config());
    const Array X = Array::ensure(X_in), D = Array::ensure(D_in);
    if (!X || !D) {
      PyErr_Clear();
      throw std::invalid_argument("set_state: X and D must be arrays of numbers");
    }
    if (X.ndim() != 2 || X.shape(0) != n || X.shape(1) != 3)
      throw std::invalid_argument("set_state: X has shape " + shape_text(X) + "; expected (" +
                                  std::to_string(n) +
                                  ", 3) (rod.base_pairs points, of all rods with [[rods]]; Å)");
    if (D.ndim() != 3 || D.shape(0) != n || D.shape(1) != 3 || D.shape(2) != 3)
      throw std::invalid_argument("set_state: D has shape " + shape_text(D) + "; expected (" +
                                  std::to_string(n) +
                                  ", 3, 3) (row i of D[k]: the unit vector D^(i+1) at point k)");
    rod::RodState st;
    st.X.resize(n);
    st.D.resize(n);
    const double* x = X.data();
    const double* d = D.data();
    for (int k = 0; k < n; ++k)
      for (int c = 0; c < 3; ++c) {
        st.X[k][c] = x[3 * k + c];
        for (int i = 0; i < 3; ++i) st.D[k](c, i) = d[9 * k + 3 * i + c];
      }
    s().set_rod_state(std::move(st), "set_state");
  }

  py::array_t<double> fluid_velocity() {
    const int N = s().params().stepper.grid.n;
    const auto u = s().system().whole_velocity(scratch_);
    const std::size_t n3 = std::size_t(N) * N * N;
    py::array_t<double> a({py::ssize_t(3), py::ssize_t(N), py::ssize_t(N), py::ssize_t(N)});
    double* p = a.mutable_data();
    for (int c = 0; c < 3; ++c)
      for (std::size_t q = 0; q < n3; ++q) p[c * n3 + q] = u[c][q] * units::ns;  // Å/s → Å/ns
    return a;
  }

  py::dict observables() {
    s();  // not while run() advances it
    const auto& rows = run_->rows();
    const py::ssize_t R = py::ssize_t(rows.size());
    py::dict d;
    py::array_t<std::int64_t> step(R);
    py::array_t<double> time(R);
    for (py::ssize_t r = 0; r < R; ++r) {
      step.mutable_data()[r] = rows[r].step;
      time.mutable_data()[r] = rows[r].time_us;
    }
    d["step"] = step;
    d["time_us"] = time;
    for (const io::ObservableField& f : io::observable_fields()) {
      py::array_t<double> col(R);
      for (py::ssize_t r = 0; r < R; ++r) col.mutable_data()[r] = rows[r].*(f.member);
      d[f.name] = col;
    }
    // where the files name the rods: rods.csv's columns (each rod's writhe, twist and link, each
    // pair of closed rods' linking number)
    const std::vector<rod::RodRange>& ranges = s().rod_ranges();
    if (rod::names_rods(ranges))
      for (const io::RodColumn& c : io::rod_columns(ranges)) {
        py::array_t<double> col(R);
        for (py::ssize_t r = 0; r < R; ++r) col.mutable_data()[r] = c.value(rows[r]);
        d[c.name.c_str()] = col;
      }
    return d;
  }

  py::list rods() {
    py::list out;
    const auto& rp = s().rods();
    const auto& g = s().rod_ranges();
    for (std::size_t r = 0; r < rp.size(); ++r) {
      py::dict d;
      d["start"] = g[r].offset;
      d["stop"] = g[r].offset + g[r].n;
      d["closed"] = g[r].closed;
      out.append(d);
    }
    return out;
  }

  const config::Config& config() { return run_->config(); }

 private:
  std::unique_ptr<driver::Run> run_;
  std::vector<double> scratch_;
  std::atomic<bool> running_{false};
};

}  // namespace

PYBIND11_MODULE(_core, m) {
  m.doc() = "The compiled core of ibrod (use the package `ibrod`, which wraps it).";
  py::register_exception<ConfigError>(m, "ConfigError", PyExc_ValueError);
  py::register_exception<RunError>(m, "RunError", PyExc_RuntimeError);

  py::class_<config::Config>(m, "Config", R"doc(
A configuration of ibrod: every key of docs/config.md, with its default.

Config(path=None) reads a TOML file (the same file `ibrod run CONFIG` reads) on top of the
defaults; Config() is the defaults. Keys are set and read as cfg["section.key"] (the package's
Config adds item access); a bad key or value raises ibrod.ConfigError with the message
`ibrod run --set` prints.
)doc")
      .def(py::init([](const std::optional<std::string>& path) {
             return config::load_config(path.value_or(""));
           }),
           py::arg("path") = py::none(), "Read a TOML file (None: the defaults).")
      .def(
          "_set_toml",
          [](config::Config& c, const std::string& key, const std::string& value) {
            config::apply_override(c, key + "=" + value);
          },
          py::arg("key"), py::arg("value"),
          "Set one key from a TOML value text, exactly as `--set key=value`.")
      .def("to_toml", &config::to_toml,
           "The resolved configuration as a TOML document (every key; config.toml of a run).")
      .def("describe", &config::describe,
           "One line per key: name = value # unit and meaning (as `ibrod check` prints).")
      .def("validate", &config::validate,
           "The cross-key checks of `ibrod run` (the ring fits in the box, …); raises "
           "ibrod.ConfigError.")
      .def("derived", &config::derived_report,
           "Derived quantities as `ibrod check` prints them (h, Δs, r0, Debye length, steps, "
           "memory).")
      .def(
          "_assign", [](config::Config& a, const config::Config& b) { a = b; }, py::arg("other"),
          "Make this configuration a copy of other.");

  py::class_<PySimulation>(m, "Simulation", R"doc(
One trajectory of ibrod, on the same C++ core as `ibrod run`.

Simulation(cfg, output=None, overwrite=False, progress=False): builds the initial state of cfg
(the twisted circle, or rod.initial_shape). With output="DIR" the run writes the usual run
directory (config.toml, timeseries.csv, trajectory.h5md, checkpoint.bin, final_state.csv,
summary.json; docs/outputs.md); an existing non-empty DIR is refused unless overwrite=True.
With output=None nothing is written. progress=True prints the CLI's progress lines.
)doc")
      .def(py::init<const config::Config&, std::optional<std::string>, bool, bool>(),
           py::arg("cfg"), py::arg("output") = py::none(), py::arg("overwrite") = false,
           py::arg("progress") = false)
      .def("run", &PySimulation::run, py::arg("steps") = py::none(),
           py::arg("until_us") = py::none(), R"doc(
Advance the simulation in C++ (the GIL released): run(steps=K) takes K steps of time.dt_ns;
run(until_us=T) runs until the simulated time T µs; run() runs to time.t_end_us. Each call is a
segment of one run: rows of the time series every output.every_steps and at the segment's end,
frames and checkpoints as `ibrod run` writes them, the stop rules (a fluid at rest:
stop_reason "equilibrium") and the blow-up checks (ibrod.RunError), and with an output
directory the final files after every segment (time.t_end_us in config.toml follows the end of
the latest segment). Ctrl-C stops at the end of the current step (after a checkpoint) and raises
KeyboardInterrupt. Returns {"steps", "time_us", "stop_reason", "ms_per_step", "wall_s"}.
)doc")
      .def_property_readonly("positions", &PySimulation::positions,
                             "Rod positions, numpy (n, 3), Å (a copy).")
      .def_property_readonly("triads", &PySimulation::triads,
                             "Rod triads, numpy (n, 3, 3): row i of triads[k] is the unit "
                             "vector D^(i+1) at point k (D³ the tangent director). A copy.")
      .def("set_state", &PySimulation::set_state, py::arg("X"), py::arg("D"), R"doc(
Replace the rod's state: X (n, 3) positions in Å, D (n, 3, 3) triads (row i of D[k] is
D^(i+1)), n = rod.base_pairs. Checked: every value finite, neighbouring points (the closing
pair too) 0.5 to 1.5 rod.rise_A apart, each triad orthonormal to 1e-3 and right-handed; else
ValueError naming the point. The fluid is left as it is.
)doc")
      .def_property_readonly("fluid_velocity", &PySimulation::fluid_velocity,
                             "Fluid velocity, numpy (3, N, N, N) = (component, i, j, k) at "
                             "x = (i, j, k) h, Å/ns (a copy; the layout of velocity.npy).")
      .def("observables", &PySimulation::observables,
           "The time series so far as a dict of numpy arrays: step, time_us and every column "
           "of timeseries.csv (energies in kT, lengths in Å; docs/outputs.md); with several "
           "rods also writhe_r, twist_r, link_r of each rod r (rods.csv's columns).")
      .def_property_readonly("rods", &PySimulation::rods,
                             "The rods: a list of dicts {start, stop, closed}, one per rod, "
                             "so that positions[start:stop] are that rod's points (one entry "
                             "for a run of one rod; [[rods]]: docs/config.md).")
      .def_property_readonly(
          "step", [](PySimulation& p) { return p.s().step_count(); }, "Steps taken.")
      .def_property_readonly(
          "time_us", [](PySimulation& p) { return p.s().time() / 1e-6; }, "Simulated time, µs.")
      .def_property_readonly(
          "dt_ns", [](PySimulation& p) { return p.s().dt() / 1e-9; }, "Time step Δt, ns.")
      .def_property_readonly(
          "config", [](PySimulation& p) { return config::Config(p.config()); },
          "The configuration as run (a copy; time.t_end_us: the end of the latest segment).");
}
