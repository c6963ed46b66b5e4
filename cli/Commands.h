// The subcommands of `surftrack`; each returns the process exit status.
#pragma once

#include <string>
#include <vector>

namespace surftrack::cli {

int runMesh(const std::vector<std::string>& args);
int runInfo(const std::vector<std::string>& args);
int runDemo(const std::vector<std::string>& args);
int runLabels(const std::vector<std::string>& args);

}  // namespace surftrack::cli
