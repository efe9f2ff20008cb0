#pragma once
// A user's table of object properties, for importers of formats that do not record them
// (the MIT push dataset names its object, "shape=rect1", but not its mass). CSV with a
// header, read with fast-cpp-csv-parser; `#` lines are comments:
//
//   name,mass,inertia,com_height,patch,source
//   rect1,0.835,1.13e-3,0.0065,rectangle 0.09 0.09,estimate: 90x90x13 mm steel plate
//
// Required columns: name, mass [kg], inertia [kg m^2] (about the vertical axis through the
// CM), com_height [m]. Optional: patch (log-format.md), cm_offset ("DX DY" [m]: the CM in
// the frame the recording tracks, object axes, where that frame's origin is not the CM),
// source (free text: where the values come from; copied into the imported logs' metadata).
// Column order is free.

#include <Eigen/Core>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

namespace slideid {

/// One object's known properties.
struct ObjectProperties {
  double mass_kg = 0.0;       ///< > 0
  double inertia_kgm2 = 0.0;  ///< > 0, about the vertical axis through the CM
  double com_height_m = 0.0;  ///< >= 0
  std::string patch_spec;     ///< "rectangle W L" etc.; empty when the table has none
  /// The CM in the frame whose pose the recording tracks [m, object axes]; zero where that
  /// frame's origin is the CM.
  Eigen::Vector2d cm_offset_m = Eigen::Vector2d::Zero();
  std::string source;  ///< where the values come from; may be empty
};

/// Object name -> properties.
using ObjectTable = std::map<std::string, ObjectProperties>;

/// Reads a table. Throws std::runtime_error naming the file, the line and the column for a
/// missing column, a bad or out-of-range number, a bad patch or a name given twice.
ObjectTable ReadObjectTable(const std::string& path);

}  // namespace slideid
