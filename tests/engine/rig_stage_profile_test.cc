// Rig::FromConfig and the stage's register profile: a built-in one by name, a lab's own file by
// [stage] profile_file, and a file that cannot work refused with the key, the file and the line.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "daemon/config/config.h"
#include "daemon/engine/rig.h"
#include "drivers/stage/profile_file.h"

namespace brdf::daemon {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

class RigStageProfile : public ::testing::Test {
 protected:
  void TearDown() override { std::filesystem::remove(path_); }
  std::string Write(const std::string& text) {
    std::ofstream(path_) << text;
    return path_;
  }
  const std::string path_ =
      ::testing::TempDir() + "/rig-profile-" + std::to_string(getpid()) + ".toml";
};

TEST_F(RigStageProfile, ALabsOwnFileIsUsedAndABadOneIsRefusedNamingFileKeyAndLine) {
  Config config;
  config.stage.profile_file = Write(std::string(drivers::stage::BuiltinProfileText("moons")));
  auto rig = Rig::FromConfig(config, Rig::Options());
  ASSERT_TRUE(rig.ok()) << rig.status().message();
  EXPECT_THAT((*rig)->GetStatus().stage.model, HasSubstr("profile file " + path_));

  std::string bad(drivers::stage::BuiltinProfileText("moons"));
  bad.replace(bad.find("words = 2\n"), 10, "words = 4\n");
  config.stage.profile_file = Write(bad);
  auto refused = Rig::FromConfig(config, Rig::Options());
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kConfigurationError);
  EXPECT_THAT(refused.status().message(),
              AllOf(HasSubstr("config stage.profile_file"), HasSubstr(path_), HasSubstr("line "),
                    HasSubstr("position.words"), HasSubstr("fix the file")));

  config.stage.profile_file = path_ + ".missing";
  auto missing = Rig::FromConfig(config, Rig::Options());
  ASSERT_FALSE(missing.ok());
  EXPECT_THAT(missing.status().message(),
              AllOf(HasSubstr(".missing"), HasSubstr("cannot be read")));
}

}  // namespace
}  // namespace brdf::daemon
