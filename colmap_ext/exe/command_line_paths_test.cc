#include "colmap_ext/exe/command_line_paths.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace colmap {
namespace {

CommandLinePaths Parse(const std::string& command,
                       const std::vector<std::string>& args) {
  std::vector<const char*> argv = {"colmap"};
  for (const std::string& arg : args) {
    argv.push_back(arg.c_str());
  }
  return CommandLinePaths(command, static_cast<int>(argv.size()), argv.data());
}

class CommandLinePathsTest : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::path(testing::TempDir()) / "command_line_paths";
    std::filesystem::create_directories(dir_);
    empty_ = (dir_ / "empty.db").string();
    std::ofstream(empty_).close();
    missing_ = (dir_ / "missing.db").string();
  }
  std::filesystem::path dir_;
  std::string empty_;
  std::string missing_;
};

TEST_F(CommandLinePathsTest, MissingOrEmptyDatabase) {
  EXPECT_EQ(Parse("mapper", {"--database_path", missing_})
                .MissingDatabaseError(),
            "database " + missing_ +
                " does not exist (feature_extractor creates a database)");
  EXPECT_EQ(Parse("exhaustive_matcher", {"--database_path=" + empty_})
                .MissingDatabaseError(),
            "database " + empty_ +
                " is empty (feature_extractor fills a database)");
  // Commands that create their database.
  EXPECT_EQ(Parse("feature_extractor", {"--database_path", missing_})
                .MissingDatabaseError(),
            "");
  // A project file names its database.
  const std::string project = (dir_ / "project.ini").string();
  std::ofstream(project) << "[General]\n  database_path=" << missing_ << "\r\n";
  EXPECT_NE(Parse("mapper", {"--project_path", project})
                .MissingDatabaseError()
                .find(missing_),
            std::string::npos);
}

TEST_F(CommandLinePathsTest, MissingPaths) {
  const std::string image_path = dir_.string();
  EXPECT_EQ(Parse("mapper", {"--image_path", image_path, "--database_path",
                             empty_, "--Mapper.num_threads", "2"})
                .MissingPaths(),
            "");
  EXPECT_EQ(Parse("mapper", {"--input_path=" + missing_, "--output_path",
                             (dir_ / "new").string()})
                .MissingPaths(),
            "paths that do not exist: --input_path " + missing_ +
                ", --output_path " + (dir_ / "new").string());
  // Commands that create their output folder, in an existing one.
  for (const std::string command : {"image_undistorter",
                                    "calibration_importer"}) {
    EXPECT_EQ(Parse(command, {"--output_path", (dir_ / "new").string()})
                  .MissingPaths(),
              "")
        << command;
    EXPECT_EQ(Parse(command, {"--output_path", (dir_ / "a" / "b").string()})
                  .MissingPaths(),
              "paths that do not exist: --output_path " +
                  (dir_ / "a" / "b").string())
        << command;
  }
  // An option without a value.
  EXPECT_EQ(Parse("mapper", {"--input_path"}).MissingPaths(), "");
}

}  // namespace
}  // namespace colmap
