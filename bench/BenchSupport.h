// What every benchmark here needs: comma-separated option lists, the two clocks (wall and this
// thread's CPU time), and medians.
#pragma once

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace surftrack::bench {

/// "64,128,256" -> {64, 128, 256}; throws std::invalid_argument naming `what` on a bad item.
template <class T>
std::vector<T> parseList(const std::string& text, const std::string& what) {
  std::vector<T> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size()) throw std::invalid_argument("bad " + what + " '" + item + "'");
    out.push_back(T(v));
  }
  if (out.empty()) throw std::invalid_argument("empty " + what + " list");
  return out;
}

/// A benchmark's command line, option by option: `for (Arguments args(argc, argv); args.next();)`,
/// then `args.is("--sizes")`, `args.value()` for the argument that follows the option, and
/// `args.unknown()` for one no branch took. Errors are std::invalid_argument, one line each.
class Arguments {
 public:
  Arguments(int argc, char** argv) : argc_(argc), argv_(argv) {}
  bool next() {
    if (++i_ >= argc_) return false;
    current_ = argv_[i_];
    return true;
  }
  const std::string& current() const { return current_; }
  bool is(const char* name) const { return current_ == name; }
  bool isHelp() const { return current_ == "--help" || current_ == "-h"; }
  std::string value() {
    if (i_ + 1 >= argc_) throw std::invalid_argument(current_ + " needs a value");
    return argv_[++i_];
  }
  [[noreturn]] void unknown() const {
    throw std::invalid_argument("unknown option " + current_ + " (see --help)");
  }

 private:
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string current_;
};

inline double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

inline double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// CPU seconds of all the process's threads (for parallel code, next to wallSeconds).
inline double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// The median (mean of the two middle values for an even count); NaN for no value.
inline double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Median seconds of `runs` calls of f, on the given clock; f's result is destroyed untimed.
template <class F>
double medianSeconds(int runs, F&& f, double (*clock)() = wallSeconds) {
  std::vector<double> times;
  for (int r = 0; r < runs; ++r) {
    const double start = clock();
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      times.push_back(clock() - start);
    } else {
      const auto result = f();
      times.push_back(clock() - start);
    }
  }
  return median(std::move(times));
}

}  // namespace surftrack::bench
