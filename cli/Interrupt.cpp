#include "Interrupt.h"

#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>

#include "TemporaryFiles.h"

namespace surftrack::cli {

namespace {

pid_t writerThread = 0;      ///< the thread id of main()
pthread_t writerHandle;      ///< the same thread, for pthread_kill
bool stderrIsTerminal = false;  ///< a progress line may be on it: erase it first

/// Writes a C string with write(2) (async-signal-safe, unlike stdio).
void say(const char* text) {
  for (std::size_t left = std::strlen(text); left > 0;) {
    const ssize_t n = ::write(STDERR_FILENO, text, left);
    if (n <= 0) return;
    text += n;
    left -= std::size_t(n);
  }
}

extern "C" void onTermination(int signal) {
  if (::syscall(SYS_gettid) != writerThread) {
    // The registry may be being changed on the writer thread right now, with the signal
    // blocked there: hand the signal to it, which handles it once the change is complete.
    pthread_kill(writerHandle, signal);
    return;
  }
  removeLiveTemporaries();
  if (stderrIsTerminal) say("\r\033[K");
  say(signal == SIGINT ? "surftrack: interrupted\n" : "surftrack: terminated\n");
  // End by the signal itself: its default action, unblocked (a handler runs with it blocked).
  std::signal(signal, SIG_DFL);
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, signal);
  pthread_sigmask(SIG_UNBLOCK, &set, nullptr);
  ::raise(signal);
  ::_exit(128 + signal);  // (not reached)
}

}  // namespace

void removeTemporariesOnTermination() {
  writerThread = pid_t(::syscall(SYS_gettid));
  writerHandle = pthread_self();
  stderrIsTerminal = ::isatty(STDERR_FILENO);
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = onTermination;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  for (int signal : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction previous;
    // A signal ignored by the parent (nohup, a background job of a non-interactive shell)
    // stays ignored.
    if (sigaction(signal, nullptr, &previous) == 0 && previous.sa_handler == SIG_IGN) continue;
    sigaction(signal, &action, nullptr);
  }
}

}  // namespace surftrack::cli
