// The temporary files and directories a process is writing — the hidden names its outputs are
// written under before a rename puts them in place (writeFileAtomically, the CLI's staged
// outputs) — in one registry, so that a handler of SIGINT or SIGTERM can remove them: a program
// stopped while writing leaves neither a partial output nor a temporary behind (docs/cli.md,
// "Output mesh formats"). Without a handler (the library in another program) the registry
// only records names.
#pragma once

#include <csignal>
#include <cstdint>
#include <string>

namespace surftrack {

/// `path` registered as a live temporary for the lifetime of this object (which neither
/// creates nor removes it). Register before creating the file, so that no moment exists when
/// the file is there and not registered; keep it registered until the file is renamed or
/// removed.
class LiveTemporary {
 public:
  enum class Kind { File, Directory };
  explicit LiveTemporary(const std::string& path, Kind kind = Kind::File);
  ~LiveTemporary();
  LiveTemporary(LiveTemporary&& other) noexcept : id_(other.id_) { other.id_ = 0; }
  LiveTemporary& operator=(LiveTemporary&&) = delete;
  LiveTemporary(const LiveTemporary&) = delete;

 private:
  std::uint64_t id_ = 0;
};

/// Removes every live temporary: unlink() each file, then rmdir() each directory (emptied by
/// the first step: every file written into one is registered). Only async-signal-safe calls on
/// names prepared beforehand, so a signal handler may call it — on the thread that registers
/// the names, which changes the registry with the termination signals blocked: the handler
/// never sees it half-changed (cli/Interrupt.cpp sends every such signal to that thread).
void removeLiveTemporaries() noexcept;

/// SIGINT, SIGTERM and SIGHUP blocked on the calling thread for the lifetime of this object: a
/// step that must not be cut in two (a change of the registry, outputs moved into place) runs
/// whole, and a signal arriving meanwhile is handled after it.
class TerminationSignalsDeferred {
 public:
  TerminationSignalsDeferred();
  ~TerminationSignalsDeferred();
  TerminationSignalsDeferred(const TerminationSignalsDeferred&) = delete;
  TerminationSignalsDeferred& operator=(const TerminationSignalsDeferred&) = delete;

 private:
  sigset_t previous_;
};

}  // namespace surftrack
