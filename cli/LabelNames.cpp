#include "LabelNames.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace surftrack::cli {

namespace fs = std::filesystem;

LabelNames readLabelNames(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw std::runtime_error("cannot read label names '" + path + "': it is a directory");
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read label names '" + path + "': no such readable file");
  LabelNames names;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    std::istringstream fields(line);
    std::string first;
    if (!(fields >> first) || first[0] == '#') continue;
    const std::optional<LabelValue> value = LabelValue::parse(first);  // exact: 64-bit ids too
    std::string name;
    if (!value || !(fields >> name))
      throw std::runtime_error("cannot read label names '" + path + "': line " + std::to_string(number) +
                               " is not 'value name'");
    names[*value] = name;
  }
  if (in.bad()) throw std::runtime_error("cannot read label names '" + path + "': read error");
  return names;
}

std::optional<std::string> labelNamesSidecar(const std::string& volumePath) {
  fs::path p(volumePath);
  std::vector<fs::path> candidates;
  if (p.extension() == ".gz") {
    p.replace_extension();                          // aal.nii.gz -> aal.nii
    candidates.push_back(fs::path(p).concat(".txt"));  // aal.nii.txt
  }
  candidates.push_back(fs::path(p).replace_extension(".txt"));  // aal.txt
  std::error_code ec;
  for (const fs::path& c : candidates)
    if (fs::is_regular_file(c, ec)) return c.string();
  return std::nullopt;
}

std::string labelName(const LabelNames& names, const LabelValue& label) {
  const auto it = names.find(label);
  return it != names.end() ? it->second : "label" + label.text();
}

}  // namespace surftrack::cli
