#pragma once
// Progress of a run on one stream. On a terminal: one line rewritten in place ('\r'), at most a
// few times a second. Otherwise (a log file, a pipe): plain lines, the first one at once, then at
// most one per `interval_s` (10 s), and always the last one, so a week-long run never floods its
// log. Messages (warnings) end the in-place line first so that they are not overwritten.
#include <cstdio>
#include <string>

namespace ibrod::driver {

class Progress {
 public:
  /// out: the stream (nullptr: silent). tty: in-place updates; −1 decides by isatty(out).
  explicit Progress(std::FILE* out, int tty = -1, double interval_s = 10.0,
                    double tty_interval_s = 0.2);
  ~Progress();  // ends an in-place line

  /// Offers a progress line at wall time now_s (any monotonic clock, s). Printed if the first,
  /// if `last`, or if the interval since the previous printed line has passed. Returns whether
  /// it was printed.
  /// `force`: printed whatever the interval (the line before the first step, the first output
  /// step's), without ending an in-place line.
  bool update(const std::string& line, double now_s, bool last = false, bool force = false);
  /// Prints a line of its own (not throttled).
  void message(const std::string& line);
  /// Ends an in-place line (no-op otherwise).
  void finish_line();

  /// Whether one interval has passed since the last line (since time 0 before the first line):
  /// a caller that prints its first line at a chosen moment still prints one after an interval
  /// if that moment is late (a large grid's first output step).
  bool due(double now_s) const { return out_ && now_s - last_s_ >= interval_s_; }
  /// Whether a progress line has been printed yet.
  bool started() const { return printed_any_; }
  bool tty() const { return tty_; }

 private:
  std::FILE* out_;
  bool tty_;
  double interval_s_;
  double last_s_ = 0;
  bool printed_any_ = false;
  bool line_open_ = false;
  std::size_t last_width_ = 0;
};

}  // namespace ibrod::driver
