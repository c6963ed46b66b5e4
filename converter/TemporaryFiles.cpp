#include "TemporaryFiles.h"

#include <pthread.h>
#include <unistd.h>

#include <map>
#include <mutex>

namespace surftrack {

namespace {

struct Entry {
  std::string path;
  LiveTemporary::Kind kind;
};

/// The registry: changed under the mutex (threads) with the termination signals blocked (a
/// handler on this thread); read by removeLiveTemporaries without either.
struct Registry {
  std::mutex mutex;
  std::map<std::uint64_t, Entry> entries;
  std::uint64_t next = 1;
};

Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: a handler may run during exit
  return *r;
}

}  // namespace

TerminationSignalsDeferred::TerminationSignalsDeferred() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &set, &previous_);
}

TerminationSignalsDeferred::~TerminationSignalsDeferred() { pthread_sigmask(SIG_SETMASK, &previous_, nullptr); }

LiveTemporary::LiveTemporary(const std::string& path, Kind kind) {
  Entry entry{path, kind};  // (allocated before the signals are blocked)
  Registry& r = registry();
  const TerminationSignalsDeferred deferred;
  const std::lock_guard lock(r.mutex);
  id_ = r.next++;
  r.entries.emplace(id_, std::move(entry));
}

LiveTemporary::~LiveTemporary() {
  if (!id_) return;
  Registry& r = registry();
  const TerminationSignalsDeferred deferred;
  const std::lock_guard lock(r.mutex);
  r.entries.erase(id_);
}

void removeLiveTemporaries() noexcept {
  const Registry& r = registry();
  for (const auto& [id, e] : r.entries)
    if (e.kind == LiveTemporary::Kind::File) ::unlink(e.path.c_str());
  for (auto it = r.entries.rbegin(); it != r.entries.rend(); ++it)  // inner directories first
    if (it->second.kind == LiveTemporary::Kind::Directory) ::rmdir(it->second.path.c_str());
}

}  // namespace surftrack
