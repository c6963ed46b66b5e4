#include "LabelTable.h"

#include <sstream>

#include <nlohmann/json.hpp>

#include "Report.h"

namespace surftrack::cli {

namespace {

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char ch : text) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

}  // namespace

std::string labelTableCsv(const std::vector<LabelRow>& rows) {
  std::ostringstream out;
  out << "label,name,voxels,voxel_volume,surfels,triangles,boundaries,euler,genus,area,volume,file\n";
  for (const LabelRow& r : rows)
    out << r.label << ',' << csvField(r.name) << ',' << r.voxels << ',' << num(r.voxelVolume, 10) << ','
        << r.surfels << ',' << r.triangles << ',' << r.boundaries << ',' << r.euler << ',' << num(r.genus)
        << ',' << num(r.area, 10) << ',' << num(r.volume, 10) << ',' << csvField(r.file) << '\n';
  return out.str();
}

nlohmann::ordered_json labelTableJson(const std::vector<LabelRow>& rows) {
  nlohmann::ordered_json table = nlohmann::ordered_json::array();
  for (const LabelRow& r : rows)
    table.push_back({{"label", labelJson(r.label)},
                     {"name", r.name},
                     {"voxels", r.voxels},
                     {"voxel_volume", number(r.voxelVolume)},
                     {"surfels", r.surfels},
                     {"triangles", r.triangles},
                     {"boundaries", r.boundaries},
                     {"euler", r.euler},
                     {"genus", number(r.genus)},
                     {"area", number(r.area)},
                     {"volume", number(r.volume)},
                     {"file", r.file}});
  return table;
}

}  // namespace surftrack::cli
