#include "colmap_ext/controllers/option_values.h"

#include "colmap/util/enum_utils.h"

#include <limits>
#include <stdexcept>

#include <gtest/gtest.h>

namespace colmap {
namespace {

MAKE_ENUM_CLASS(TestResidual, 0, ANGULAR, PIXEL);

TEST(OptionValues, EnumValuesInAnyLetterCase) {
  EXPECT_EQ(EnumOptionValue("Mapper.residual", "pixel",
                            TestResidualFromString),
            TestResidual::PIXEL);
  EXPECT_EQ(EnumOptionValue("Mapper.residual", "Angular",
                            TestResidualFromString),
            TestResidual::ANGULAR);
  try {
    EnumOptionValue("Mapper.residual", "cubic", TestResidualFromString);
    ADD_FAILURE() << "cubic is no value of the enum";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "--Mapper.residual: unknown value 'cubic'");
  }
}

TEST(OptionValues, GivenValuesAndFiniteNumbers) {
  namespace po = boost::program_options;
  bool flag = false;
  int count = 0;
  double ratio = 0;
  std::string path;
  po::options_description description;
  description.add_options()("flag", po::value<bool>(&flag)->default_value(false))(
      "count", po::value<int>(&count)->default_value(3))(
      "ratio", po::value<double>(&ratio)->default_value(1.0))(
      "image_path", po::value<std::string>(&path)->default_value(""));
  const char* argv[] = {"colmap", "--ratio", "nan", "--image_path", "x",
                        "--flag", "1"};
  po::variables_map vmap;
  po::store(po::parse_command_line(7, argv, description), vmap);
  po::notify(vmap);

  EXPECT_THROW(CheckFiniteOptions(vmap, {{"ratio", &ratio}}),
               std::invalid_argument);
  ratio = 2;
  EXPECT_NO_THROW(CheckFiniteOptions(vmap, {{"ratio", &ratio}}));
  // The paths and the options left at their defaults are not listed.
  EXPECT_EQ(InvalidOptionsMessage(vmap, {{"flag", &flag}}, {{"count", &count}},
                                  {{"ratio", &ratio}}, {{"image_path", &path}}),
            "Invalid options provided; the values given: --flag 1 --ratio "
            "2.000000");
  EXPECT_EQ(InvalidOptionsMessage(vmap, {}, {{"count", &count}}, {}, {}),
            "Invalid options provided.");
}

}  // namespace
}  // namespace colmap
