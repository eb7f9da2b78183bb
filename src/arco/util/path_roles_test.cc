#include "arco/util/path_roles.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "arco/testing/temp_dir.h"
#include "arco/util/file_io.h"

namespace arco {
namespace {

namespace fs = std::filesystem;

std::string CheckOne(const std::string& input, const std::string& output, bool folder = false) {
  PathRoles roles;
  if (folder) {
    roles.AddInput("RESULT_DIR", input);
  } else {
    roles.AddInput("INPUT", input);
  }
  roles.AddOutput("-o", output);
  const Status s = roles.Check();
  return s.ok() ? "ok" : s.message();
}

class PathRolesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(MakeDirectories(tmp_ / "res/arco").ok());
    std::ofstream(tmp_ / "m.wav") << "recording";
    std::ofstream(tmp_ / "res/result.json") << "{}";
    fs::create_symlink(tmp_ / "m.wav", tmp_ / "link.wav");
    fs::create_symlink(tmp_ / "res", tmp_ / "reslink");
    fs::create_hard_link(tmp_ / "m.wav", tmp_ / "hard.wav");
  }
  testing::TempDir tmp_;
};

TEST_F(PathRolesTest, AnOutputThatIsAnInputFileIsRefused) {
  const std::string m = tmp_ / "m.wav";
  EXPECT_EQ(CheckOne(m, m),
            m + ": -o is the input INPUT; an output never replaces an input (choose another "
                "path)");
  // A link names the file it stands for.
  EXPECT_NE(CheckOne(m, tmp_ / "link.wav").find("is the input INPUT (" + m + ")"),
            std::string::npos);
  // Other spellings of the same file: through "..", a symbolic link, a hard link.
  for (const std::string& other : {tmp_ / "res/../m.wav", tmp_ / "./m.wav", tmp_ / "link.wav",
                                   tmp_ / "hard.wav"}) {
    EXPECT_NE(CheckOne(m, other).find("is the input INPUT"), std::string::npos)
        << other;
    EXPECT_NE(CheckOne(other, m).find("is the input INPUT"), std::string::npos) << other;
  }
}

TEST_F(PathRolesTest, AnOutputInsideAnInputFolderIsRefused) {
  const std::string res = tmp_ / "res";
  EXPECT_EQ(CheckOne(res, tmp_ / "res/result.json", true),
            tmp_ / "res/result.json" + ": -o is inside the input folder RESULT_DIR (" + res +
                "); an output never goes into an input (choose a path outside it)");
  EXPECT_NE(CheckOne(res + "/", tmp_ / "reslink/arco/new.npy", true).find("inside the input"),
            std::string::npos);
  EXPECT_NE(CheckOne(res, tmp_ / "res/not/yet/there.csv", true).find("inside the input"),
            std::string::npos);
  // A folder that would be replaced with an input inside it.
  EXPECT_NE(CheckOne(tmp_ / "res/result.json", res).find("-o contains the input INPUT"),
            std::string::npos);
}

TEST_F(PathRolesTest, OtherPathsAndOwnedFoldersAreFine) {
  EXPECT_EQ(CheckOne(tmp_ / "m.wav", tmp_ / "p.csv"), "ok");
  EXPECT_EQ(CheckOne(tmp_ / "res", tmp_ / "res2/x.csv", true), "ok");  // a name prefix only
  EXPECT_EQ(CheckOne(tmp_ / "res", tmp_ / "eval.json", true), "ok");
  EXPECT_EQ(CheckOne("", tmp_ / "eval.json"), "ok");
  PathRoles owned;
  owned.AddOwnedFolder("CAPTURE", tmp_ / "res");
  owned.AddOutput("CAPTURE", tmp_ / "res/keypoints2d.npy");
  EXPECT_TRUE(owned.Check().ok());
  owned.AddInput("--camera", tmp_ / "res/keypoints2d.npy");
  EXPECT_FALSE(owned.Check().ok());  // still no output onto an input file
  PathRoles whole;
  whole.AddOwnedFolder("CAPTURE", tmp_ / "res");
  whole.AddOutput("-o", tmp_ / "res/");
  EXPECT_FALSE(whole.Check().ok());  // the owned folder itself is not an output
}

TEST_F(PathRolesTest, TwoOutputsOnOneFileAreRefused) {
  PathRoles roles;
  roles.AddInput("INPUT", tmp_ / "m.wav");
  roles.AddOutput("-o", tmp_ / "p.csv");
  roles.AddOutput("--notes", tmp_ / "res/../p.csv");
  const Status s = roles.Check();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("given for two outputs (-o and --notes)"), std::string::npos);
}

TEST(ResolvePath, RelativeTrailingSlashAndDotDot) {
  const std::string cwd = fs::current_path().string();
  EXPECT_EQ(ResolvePath("no/such/../x/"), cwd + "/no/x");
  EXPECT_EQ(ResolvePath("."), cwd);
  EXPECT_EQ(ResolvePath(""), "");
  EXPECT_TRUE(PathIsInside("/a/b/c", "/a/b"));
  EXPECT_FALSE(PathIsInside("/a/bc", "/a/b"));
  EXPECT_FALSE(PathIsInside("/a/b", "/a/b"));
  EXPECT_TRUE(PathIsInside("/a", "/"));
}

}  // namespace
}  // namespace arco
