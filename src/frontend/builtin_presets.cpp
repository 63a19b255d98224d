#include "cvo_odometry/frontend/builtin_presets.hpp"

#include <sstream>
#include <stdexcept>

#include "cvo_odometry/frontend/dataset_files.hpp"

namespace cvo {

void applyPreset(const std::string& name_or_path, OdometrySettings* settings) {
  const auto& presets = builtInPresets();
  const auto it = presets.find(name_or_path);
  if (it != presets.end()) {
    std::istringstream text(it->second);
    readSettings(text, name_or_path, settings);
    return;
  }
  if (!fileExists(name_or_path)) {
    std::string names;
    for (const auto& [name, text] : presets)
      names += (names.empty() ? "" : ", ") + name;
    throw std::runtime_error("no preset '" + name_or_path + "': give a preset file or one of " +
                             names);
  }
  loadSettings(name_or_path, settings);
}

}  // namespace cvo
