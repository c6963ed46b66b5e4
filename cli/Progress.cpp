#include "Progress.h"

#include <cstdio>
#include <unistd.h>

namespace surftrack::cli {

namespace {
constexpr auto kDelay = std::chrono::seconds(1);  // draw nothing for work shorter than this
constexpr auto kPeriod = std::chrono::milliseconds(100);
constexpr int kBarWidth = 20;
}  // namespace

bool Progress::wanted(bool quiet) { return !quiet && ::isatty(STDERR_FILENO); }

Progress::Progress(bool enabled) : enabled_(enabled), start_(std::chrono::steady_clock::now()) {
  if (enabled_) thread_ = std::thread([this] { run(); });
}

Progress::~Progress() { finish(); }

void Progress::stage(int index, int stageCount, const std::string& name) {
  if (!enabled_) return;
  std::lock_guard lock(mutex_);
  stageIndex_ = index;
  stageCount_ = stageCount > 0 ? stageCount : 1;
  stageName_ = name;
  count_ = 0;
  unit_ = "";
}

void Progress::count(std::size_t n, const char* unit) {
  if (!enabled_) return;
  {
    std::lock_guard lock(mutex_);
    unit_ = unit;
  }
  count_ = n;
}

void Progress::finish() {
  if (!enabled_) return;
  {
    std::lock_guard lock(mutex_);
    if (stop_) return;
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  if (drawn_) {
    std::fputs("\r\033[K", stderr);  // erase the line
    std::fflush(stderr);
  }
}

void Progress::run() {
  std::unique_lock lock(mutex_);
  if (wake_.wait_for(lock, kDelay, [this] { return stop_; })) return;
  while (!stop_) {
    draw(false);
    wake_.wait_for(lock, kPeriod, [this] { return stop_; });
  }
}

void Progress::draw(bool) {
  // Called with mutex_ held.
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // The bar fills with the stages done; the current stage's cell blinks between states.
  const int done = stageIndex_ * kBarWidth / stageCount_;
  const int upto = (stageIndex_ + 1) * kBarWidth / stageCount_;
  const int phase = int(elapsed * 10) % (upto - done > 0 ? upto - done : 1);
  std::string bar;
  for (int i = 0; i < kBarWidth; ++i)
    bar += i < done ? "#" : (i < upto && i - done <= phase) ? "=" : ".";
  char countText[64] = "";
  const std::size_t n = count_;
  if (n > 0) {
    if (n >= 1000000) std::snprintf(countText, sizeof countText, "  %.2f M %s", n / 1e6, unit_);
    else std::snprintf(countText, sizeof countText, "  %zu %s", n, unit_);
  }
  std::fprintf(stderr, "\r\033[Ksurftrack [%s] %d/%d %s%s  %.1f s", bar.c_str(), stageIndex_ + 1,
               stageCount_, stageName_.c_str(), countText, elapsed);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace surftrack::cli
