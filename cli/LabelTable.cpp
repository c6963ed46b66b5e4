#include "LabelTable.h"

#include <algorithm>

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
  const bool smoothed = std::any_of(rows.begin(), rows.end(), [](const LabelRow& r) { return r.smoothed; });
  const bool tree = std::any_of(rows.begin(), rows.end(), [](const LabelRow& r) { return r.mergeLevels >= 0; });
  const bool missing = std::any_of(rows.begin(), rows.end(), [](const LabelRow& r) { return !r.noFile.empty(); });
  const bool decimated = std::any_of(rows.begin(), rows.end(), [](const LabelRow& r) { return r.decimated; });
  const bool pinched = std::any_of(rows.begin(), rows.end(), [](const LabelRow& r) { return r.pinchCopies || r.pinchedEdges; });
  out << "label,name,voxels,voxel_volume,surfels,triangles,boundaries,euler,genus,area,volume,"
      << (smoothed ? "volume_before_smoothing,max_vertex_displacement," : "")
      << (decimated ? "triangles_before_decimation,target_triangles,volume_before_decimation," : "")
      << (pinched ? "pinch_copies,pinched_edges,joined_edges," : "") << "file"
      << (tree ? ",merge_levels" : "") << (missing ? ",no_file" : "") << "\n";
  for (const LabelRow& r : rows) {
    out << r.label << ',' << csvField(r.name) << ',' << r.voxels << ',' << num(r.voxelVolume, 10) << ','
        << r.surfels << ',' << r.triangles << ',' << r.boundaries << ',' << r.euler << ',' << num(r.genus)
        << ',' << num(r.area, 10) << ',' << num(r.volume, 10) << ',';
    if (smoothed) out << num(r.volumeBeforeSmoothing, 10) << ',' << num(r.maxDisplacement, 10) << ',';
    if (decimated)
      out << r.trianglesBeforeDecimation << ',' << r.targetTriangles << ',' << num(r.volumeBeforeDecimation, 10) << ',';
    if (pinched) out << r.pinchCopies << ',' << r.pinchedEdges << ',' << r.joinedEdges << ',';
    out << csvField(r.file);
    if (tree) out << ',' << (r.mergeLevels >= 0 ? std::to_string(r.mergeLevels) : std::string());
    if (missing) out << ',' << csvField(r.noFile);
    out << '\n';
  }
  return out.str();
}

nlohmann::ordered_json labelTableJson(const std::vector<LabelRow>& rows) {
  nlohmann::ordered_json table = nlohmann::ordered_json::array();
  for (const LabelRow& r : rows) {
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
                     {"file", r.noFile.empty() ? nlohmann::ordered_json(r.file) : nlohmann::ordered_json()}});
    if (r.smoothed) {
      table.back()["volume_before_smoothing"] = number(r.volumeBeforeSmoothing);
      table.back()["max_vertex_displacement"] = number(r.maxDisplacement);
    }
    if (r.decimated) {
      table.back()["triangles_before_decimation"] = r.trianglesBeforeDecimation;
      table.back()["target_triangles"] = r.targetTriangles;
      table.back()["volume_before_decimation"] = number(r.volumeBeforeDecimation);
    }
    if (r.pinchCopies || r.pinchedEdges) {
      table.back()["pinch_copies"] = r.pinchCopies;
      table.back()["pinched_edges"] = r.pinchedEdges;
      table.back()["joined_edges"] = r.joinedEdges;
    }
    if (r.mergeLevels >= 0) table.back()["merge_levels"] = r.mergeLevels;
    if (!r.noFile.empty()) table.back()["no_file"] = r.noFile;
  }
  return table;
}

}  // namespace surftrack::cli
