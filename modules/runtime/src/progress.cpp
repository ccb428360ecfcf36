#include "viewline/runtime/progress.h"

#include <unistd.h>

#include <utility>

namespace viewline::runtime {

Progress::Progress(std::string what, long total, std::FILE* out, int interactive, double min_interval_s)
    : what_(std::move(what)), total_(total), out_(out), min_interval_s_(min_interval_s),
      last_wall_(std::chrono::steady_clock::now()) {
  interactive_ = interactive < 0 ? (out_ != nullptr && ::isatty(::fileno(out_)) != 0) : interactive > 0;
}

Progress Progress::quiet() { return Progress(); }

Progress::Progress(Progress&& o) noexcept
    : what_(std::move(o.what_)), total_(o.total_), out_(o.out_), interactive_(o.interactive_),
      min_interval_s_(o.min_interval_s_), last_printed_(o.last_printed_), printed_any_(o.printed_any_), last_done_(o.last_done_),
      last_wall_(o.last_wall_), finished_(o.finished_) {
  o.out_ = nullptr;
}

Progress::~Progress() { finish(); }

void Progress::print(long done) {
  if (interactive_) std::fprintf(out_, "\r  %s %ld / %ld", what_.c_str(), done, total_);
  else std::fprintf(out_, "  %s %ld / %ld\n", what_.c_str(), done, total_);
  std::fflush(out_);
  last_printed_ = done;
  printed_any_ = true;
  last_wall_ = std::chrono::steady_clock::now();
}

void Progress::update(long done) {
  if (out_ == nullptr || finished_) return;
  last_done_ = done;
  if (interactive_) {
    print(done);
    return;
  }
  const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_wall_).count();
  const long step = total_ >= 10 ? total_ / 10 : 1;
  if (done >= total_ || since >= min_interval_s_ || done - last_printed_ >= step) print(done);
}

void Progress::finish() {
  if (out_ == nullptr || finished_) return;
  finished_ = true;
  if (last_done_ >= 0 && (!printed_any_ || last_done_ != last_printed_)) print(last_done_);
  if (interactive_ && printed_any_) std::fputc('\n', out_);
  std::fflush(out_);
}

}  // namespace viewline::runtime
