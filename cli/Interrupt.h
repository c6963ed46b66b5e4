// Ctrl-C (SIGINT), SIGTERM and SIGHUP during a run: the temporary files and staging directories
// the tool is writing are removed before it ends, so an interrupted run leaves no partial
// output and no hidden temporary behind (docs/cli.md, "Output mesh formats").
#pragma once

namespace surftrack::cli {

/// Installs the handler of SIGINT, SIGTERM and SIGHUP; call it first in main(), on the thread
/// that writes the outputs. The handler, on that thread (a signal delivered to another thread,
/// e.g. a worker of the scan, is sent on to it), removes the live temporaries
/// (converter/TemporaryFiles.h), says "surftrack: interrupted" on stderr and ends the process by
/// the same signal, restored to its default action: the exit status is 128 + the signal's
/// number (130 for SIGINT), as the shell expects.
void removeTemporariesOnTermination();

}  // namespace surftrack::cli
