// What the command line gave COLMAP's option manager: enum values in any
// letter case, and errors that name the option (a value that is none of an
// enum's, a number that is not finite, options that fail their check).
#pragma once

#include <cctype>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <boost/program_options.hpp>

namespace colmap {

template <typename T>
using NamedOptions = std::vector<std::pair<std::string, const T*>>;

// The value of enum option `name` that `value` names in any letter case
// (`from_string` takes the upper-case names of MAKE_ENUM_CLASS); throws
// std::invalid_argument "--NAME: unknown value 'VALUE'" for none.
template <typename EnumT>
EnumT EnumOptionValue(const std::string& name,
                      const std::string& value,
                      EnumT (*from_string)(std::string_view)) {
  std::string upper = value;
  for (char& c : upper) {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  try {
    return from_string(upper);
  } catch (const std::runtime_error&) {
    throw std::invalid_argument("--" + name + ": unknown value '" + value +
                                "'");
  }
}

// Throws std::invalid_argument "--NAME: VALUE is not a finite number" for
// the first of `options` the command line set to nan or inf.
void CheckFiniteOptions(const boost::program_options::variables_map& vmap,
                        const NamedOptions<double>& options);

// "Invalid options provided; the values given: --NAME VALUE ..." with the
// options the command line set (paths left out), among which the one that
// failed its check is; "Invalid options provided." when it set none.
std::string InvalidOptionsMessage(
    const boost::program_options::variables_map& vmap,
    const NamedOptions<bool>& bools,
    const NamedOptions<int>& ints,
    const NamedOptions<double>& doubles,
    const NamedOptions<std::string>& strings);

}  // namespace colmap
