#include "colmap_ext/controllers/option_values.h"

#include <cmath>
#include <stdexcept>

namespace colmap {
namespace {

bool Given(const boost::program_options::variables_map& vmap,
           const std::string& name) {
  return vmap.count(name) && !vmap[name].defaulted();
}

}  // namespace

void CheckFiniteOptions(const boost::program_options::variables_map& vmap,
                        const NamedOptions<double>& options) {
  for (const auto& [name, value] : options) {
    if (Given(vmap, name) && !std::isfinite(*value)) {
      throw std::invalid_argument("--" + name + ": " + std::to_string(*value) +
                                  " is not a finite number");
    }
  }
}

std::string InvalidOptionsMessage(
    const boost::program_options::variables_map& vmap,
    const NamedOptions<bool>& bools,
    const NamedOptions<int>& ints,
    const NamedOptions<double>& doubles,
    const NamedOptions<std::string>& strings) {
  std::string given;
  const auto add = [&given, &vmap](const std::string& name,
                                   const std::string& value) {
    if (Given(vmap, name) && name.find("_path") == std::string::npos) {
      given += " --" + name + " " + value;
    }
  };
  for (const auto& [name, value] : bools) add(name, *value ? "1" : "0");
  for (const auto& [name, value] : ints) add(name, std::to_string(*value));
  for (const auto& [name, value] : doubles) add(name, std::to_string(*value));
  for (const auto& [name, value] : strings) add(name, *value);
  return std::string("Invalid options provided") +
         (given.empty() ? "." : "; the values given:" + given);
}

}  // namespace colmap
