// Running a job of the Python package's Dask driver (DaskJob.h).
#include "DaskJob.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "ChunkedStore.h"
#include "Extraction.h"
#include "TemporaryFiles.h"

extern char** environ;

namespace surftrack::cli {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

json numbers(const std::array<double, 3>& v) { return {v[0], v[1], v[2]}; }

/// The interpreter and the PYTHONPATH entry that find this build's Python package: the
/// package built beside this tool when it is there (SURFTRACK_PYTHON_DIR), else an installed
/// one. SURFTRACK_PYTHON names another interpreter.
std::string pythonExecutable() {
  if (const char* p = std::getenv("SURFTRACK_PYTHON"); p && *p) return p;
#ifdef SURFTRACK_PYTHON_EXECUTABLE
  return SURFTRACK_PYTHON_EXECUTABLE;
#else
  return "python3";
#endif
}

std::string builtPackageDirectory() {
#ifdef SURFTRACK_PYTHON_DIR
  std::error_code ec;
  if (fs::is_regular_file(fs::path(SURFTRACK_PYTHON_DIR) / "surftrack" / "_cli_dask.py", ec))
    return SURFTRACK_PYTHON_DIR;
#endif
  return {};
}

/// Runs `python -m surftrack._cli_dask job` with this process's environment (PYTHONPATH led by
/// the built package) and the default signal mask; returns its wait status. A Ctrl-C reaches
/// it (same process group) while this process defers its own handling (the caller's scope).
int runPython(const std::string& job) {
  const std::string python = pythonExecutable();
  std::vector<std::string> env;
  const std::string built = builtPackageDirectory();
  const char* old = std::getenv("PYTHONPATH");
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "PYTHONPATH=", 11) != 0) env.emplace_back(*e);
  std::string path = built;
  if (old && *old) {
    if (!path.empty()) path += ':';
    path += old;
  }
  if (!path.empty()) env.push_back("PYTHONPATH=" + path);
  std::vector<char*> envp;
  for (std::string& s : env) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::string a0 = python, a1 = "-m", a2 = "surftrack._cli_dask", a3 = job;
  char* argv[] = {a0.data(), a1.data(), a2.data(), a3.data(), nullptr};

  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none;
  sigemptyset(&none);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, python.c_str(), nullptr, &attr, argv, envp.data());
  posix_spawnattr_destroy(&attr);
  if (spawned != 0)
    throw std::runtime_error("--dask runs the surftrack Python package with '" + python +
                             "', which cannot be started: " + std::strerror(spawned) +
                             " (set SURFTRACK_PYTHON to an interpreter)");
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) throw std::runtime_error(std::string("waiting for the Dask driver: ") + std::strerror(errno));
  return status;
}

}  // namespace

json storeJob(const InputOptions& input, const std::string& dask, std::array<int, 3> block,
              const std::string& workDir, ImageGeometry& geometry) {
  if (!isChunkedInput(input))
    throw UsageError("--dask reads a chunked store (a zarr, OME-Zarr or N5 directory): '" + input.path +
                     "' is not one");
  const io::ChunkedStore store = io::openChunkedStore(input.path, chunkedStoreOptions(input));
  geometry = store.provider->layout().geometry;
  applyGeometryOptions(input, geometry, "LPS");
  json job;
  job["dask"] = dask;
  job["store"] = input.path;
  job["level"] = input.level.value_or(0);
  job["channel"] = input.channel ? json(*input.channel) : json(nullptr);
  job["time"] = input.time ? json(*input.time) : json(nullptr);
  job["spacing"] = numbers(geometry.spacing);
  job["origin"] = numbers(geometry.origin);
  job["direction"] = {numbers(geometry.direction[0]), numbers(geometry.direction[1]), numbers(geometry.direction[2])};
  job["block"] = {block[0], block[1], block[2]};
  job["work_dir"] = workDir.empty() ? json(nullptr) : json(fs::absolute(workDir).string());
  job["store_format"] = store.format;  // the unit of the spacing (cli/PrecomputedOutput.h, SpacingUnit)
  job["store_unit"] = store.unit;
  return job;
}

json runDaskJob(json job, const std::string& scratch, const std::string& clearOnFailure) {
  const std::string jobFile = scratch + ".job.json", resultFile = scratch + ".result.json";
  job["result"] = resultFile;
  const LiveTemporary liveJob(jobFile), liveResult(resultFile);
  struct Remove {
    std::string a, b;
    ~Remove() {
      std::error_code ignored;
      fs::remove(a, ignored);
      fs::remove(b, ignored);
    }
  } removeLater{jobFile, resultFile};
  {
    std::ofstream out(jobFile);
    out << job.dump();
    if (!out) throw std::runtime_error("cannot write '" + jobFile + "'");
  }
  int status;
  {
    // A Ctrl-C stops the driver (it gets the signal too); this process handles it once what the
    // driver wrote, which it does not know by name, is gone.
    const TerminationSignalsDeferred deferred;
    status = runPython(jobFile);
    if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0) && !clearOnFailure.empty()) {
      std::error_code ignored;
      if (fs::is_directory(clearOnFailure, ignored)) {
        for (const auto& entry : fs::directory_iterator(clearOnFailure, ignored)) fs::remove_all(entry.path(), ignored);
      } else {
        fs::remove(clearOnFailure, ignored);
      }
    }
  }
  if (WIFSIGNALED(status))
    throw std::runtime_error("the Dask driver was stopped by signal " + std::to_string(WTERMSIG(status)));
  json result;
  {
    std::ifstream in(resultFile);
    if (in) result = json::parse(in, nullptr, false);
  }
  if (WEXITSTATUS(status) != 0) {
    if (result.is_object() && result.contains("error")) throw std::runtime_error(result["error"].get<std::string>());
    throw std::runtime_error("the Dask driver failed (exit status " + std::to_string(WEXITSTATUS(status)) +
                             ", its message above); --dask needs the surftrack Python package (the _surftrack "
                             "target of this build, or pip install) and Debian's python3-dask and "
                             "python3-distributed");
  }
  if (result.is_discarded() || result.is_null())
    throw std::runtime_error("the Dask driver gave no result ('" + resultFile + "')");
  return result;
}

}  // namespace surftrack::cli
