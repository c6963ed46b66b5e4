// A progress line on stderr for work that lasts more than a second: the stage being run, a
// bar of the stages done, a count (surfels found so far) and the elapsed time. It is drawn only
// when stderr is a terminal and --quiet is off, by a background thread ten times a second, and
// erased before anything else is printed.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <thread>

namespace surftrack::cli {

class Progress {
 public:
  /// `enabled` false: every call is a no-op. Use Progress::forTerminal(quiet) normally.
  explicit Progress(bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  /// Enabled iff stderr is a terminal and not quiet.
  static bool wanted(bool quiet);

  /// Starts stage `index` (0-based) of `stageCount`, called `name`; resets the count.
  void stage(int index, int stageCount, const std::string& name);
  /// The number of items (e.g. surfels) done in this stage.
  void count(std::size_t n, const char* unit);
  /// Erases the line and stops drawing (also done by the destructor).
  void finish();

 private:
  void run();
  void draw(bool final);

  bool enabled_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool drawn_ = false;
  int stageIndex_ = 0, stageCount_ = 1;
  std::string stageName_;
  std::atomic<std::size_t> count_{0};
  const char* unit_ = "";
  std::thread thread_;
};

}  // namespace surftrack::cli
