// `surftrack labels STORE -o DIR/ --dask ADDRESS` (DaskLabels.h).
#include "DaskLabels.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "ChunkedStore.h"
#include "Extraction.h"
#include "TemporaryFiles.h"

extern char** environ;

namespace surftrack::cli {

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

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

std::vector<LabelRow> labelRowsOnDask(const LabelsOptions& o, const LabelNames& names, StagedOutputs& staged) {
  if (!isChunkedInput(o.input))
    throw UsageError("--dask reads a chunked store (a zarr, OME-Zarr or N5 directory): '" + o.input.path +
                     "' is not one");
  const io::ChunkedStore store = io::openChunkedStore(o.input.path, chunkedStoreOptions(o.input));
  ImageGeometry g = store.provider->layout().geometry;
  applyGeometryOptions(o.input, g, "LPS");
  const std::string staging = staged.stagingDirectory();

  json job;
  job["dask"] = o.dask;
  job["store"] = o.input.path;
  job["level"] = o.input.level.value_or(0);
  job["channel"] = o.input.channel ? json(*o.input.channel) : json(nullptr);
  job["time"] = o.input.time ? json(*o.input.time) : json(nullptr);
  job["spacing"] = numbers(g.spacing);
  job["origin"] = numbers(g.origin);
  job["direction"] = {numbers(g.direction[0]), numbers(g.direction[1]), numbers(g.direction[2])};
  job["background"] = o.background.text();
  job["adjacency"] = toString(o.pair);
  job["block"] = {o.block[0], o.block[1], o.block[2]};
  job["work_dir"] = o.workDir.empty() ? json(nullptr) : json(fs::absolute(o.workDir).string());
  job["staging"] = staging;
  json named = json::object();
  for (const auto& [label, name] : names) named[label.text()] = name;
  job["names"] = named;
  job["binary"] = !o.ascii;
  job["quiet"] = o.out.quiet;
  const std::string jobFile = staging + ".job.json", resultFile = staging + ".result.json";
  job["result"] = resultFile;
  const LiveTemporary liveJob(jobFile), liveResult(resultFile);
  {
    std::ofstream out(jobFile);
    out << job.dump();
    if (!out) throw std::runtime_error("cannot write '" + jobFile + "'");
  }
  struct Remove {
    std::string a, b;
    ~Remove() {
      std::error_code ignored;
      fs::remove(a, ignored);
      fs::remove(b, ignored);
    }
  } removeLater{jobFile, resultFile};

  int status;
  {
    // A Ctrl-C stops the driver (it gets the signal too); this process handles it once the
    // files the driver wrote into the staged directory, which it does not know by name, are gone.
    const TerminationSignalsDeferred deferred;
    status = runPython(jobFile);
    if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
      std::error_code ignored;
      for (const auto& entry : fs::directory_iterator(staging, ignored)) fs::remove_all(entry.path(), ignored);
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
  if (!result.is_array()) throw std::runtime_error("the Dask driver gave no table ('" + resultFile + "')");

  const double voxelVolume = std::abs(g.handedness());
  std::vector<LabelRow> rows;
  std::set<std::string> files;
  for (const json& f : result) {
    LabelRow r;
    r.label = *LabelValue::parse(f["label"].get<std::string>());
    r.name = labelName(names, r.label);
    r.voxels = f["voxels"].get<std::uint64_t>();
    r.voxelVolume = double(r.voxels) * voxelVolume;
    r.surfels = f["vertices"].get<std::size_t>();
    r.triangles = f["triangles"].get<std::size_t>();
    r.boundaries = f["boundaries"].get<std::size_t>();
    r.euler = f["euler"].get<long long>();
    r.genus = (2.0 * double(r.boundaries) - double(r.euler)) / 2.0;
    r.area = f["area"].get<double>();
    r.volume = f["volume"].get<double>();
    r.file = (fs::path(o.output) / f["file"].get<std::string>()).string();  // as the single pass names it
    if (!files.insert(r.file).second)
      throw UsageError("two labels give the file name '" + r.file + "': their names are the same");
    staged.temporaryFor(r.file);  // (written there by a reducer)
    rows.push_back(std::move(r));
  }
  std::sort(rows.begin(), rows.end(), [](const LabelRow& a, const LabelRow& b) { return a.label < b.label; });
  return rows;
}

}  // namespace surftrack::cli
