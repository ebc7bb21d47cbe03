#include "tools/brdf-sim/optics/material.h"

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "core/material/material_reader.h"

namespace brdf::sim {

Result<material::Material> LoadMaterialFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    return NotFound("material file '" + path +
                    "' cannot be opened; check the --material path (deploy/materials/ holds the "
                    "shipped ones)");
  }
  std::ostringstream text;
  text << in.rdbuf();
  return material::ReadMaterial(text.str(), path, std::filesystem::path(path).stem().string());
}

Status LoadMountedMaterial(OpticsConfig& config) {
  if (config.material_path.empty()) return Status::Ok();
  BRDF_ASSIGN_OR_RETURN(material::Material m, LoadMaterialFile(config.material_path));
  config.material = std::make_shared<const material::Material>(std::move(m));
  return Status::Ok();
}

}  // namespace brdf::sim
