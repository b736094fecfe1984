#include "driver/progress.hpp"

#include <unistd.h>

namespace ibrod::driver {

Progress::Progress(std::FILE* out, int tty, double interval_s, double tty_interval_s)
    : out_(out),
      tty_(out && (tty < 0 ? ::isatty(::fileno(out)) != 0 : tty != 0)),
      interval_s_(tty_ ? tty_interval_s : interval_s) {}

Progress::~Progress() { finish_line(); }

bool Progress::update(const std::string& line, double now_s, bool last, bool force) {
  if (!out_) return false;
  if (printed_any_ && !last && !force && now_s - last_s_ < interval_s_) return false;
  printed_any_ = true;
  last_s_ = now_s;
  if (tty_) {
    // pad with spaces over the remains of a longer previous line
    std::string padded = line;
    if (padded.size() < last_width_) padded.append(last_width_ - padded.size(), ' ');
    last_width_ = line.size();
    std::fprintf(out_, "\r%s", padded.c_str());
    line_open_ = true;
    if (last) finish_line();
  } else {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
  return true;
}

void Progress::message(const std::string& line) {
  if (!out_) return;
  finish_line();
  std::fprintf(out_, "%s\n", line.c_str());
  std::fflush(out_);
}

void Progress::finish_line() {
  if (!out_ || !line_open_) return;
  std::fputc('\n', out_);
  std::fflush(out_);
  line_open_ = false;
  last_width_ = 0;
}

}  // namespace ibrod::driver
