// Every numeric option of every command, found from the app's own definition (BuildApp, as
// `arco` builds it), has a declared range and rejects NaN, infinities, negative, huge,
// wrapping and non-numeric values at parse time: one line naming the flag, nothing run and
// nothing written (docs/architecture.md, "Validation rules").
#include "arco/cli/app.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "arco/cli/flag_names.h"
#include "arco/cli/number_option.h"
#include "arco/testing/temp_dir.h"
#include "arco/util/number_range.h"

namespace arco::cli {
namespace {

namespace fs = std::filesystem;

struct CommandPath {
  std::vector<std::string> words;  // e.g. {"calibration", "convert"}
  CLI::App* app = nullptr;
};

// Every subcommand that takes options, nested ones included (calibration show/convert).
void CollectCommands(CLI::App* app, std::vector<std::string> words, std::vector<CommandPath>* out) {
  for (CLI::App* sub : app->get_subcommands({})) {
    std::vector<std::string> path = words;
    path.push_back(sub->get_name());
    out->push_back({path, sub});
    CollectCommands(sub, path, out);
  }
}

// "FLOAT", "INT", "UINT", "TEXT", ... (get_type_name() appends the validators' descriptions).
std::string BaseType(const CLI::Option* option) {
  const std::string full = option->get_type_name();
  return full.substr(0, full.find(':'));
}

bool IsNumeric(const CLI::Option* option) {
  const std::string type = BaseType(option);
  return type == "FLOAT" || type == "INT" || type == "UINT" || type == "NUMBER";
}

// The declared range read back from the validator's description ("(0, 1000]").
NumberRange ParseRange(const std::string& text) {
  NumberRange range;
  range.min_open = text.front() == '(';
  range.max_open = text.back() == ')';
  const size_t comma = text.find(", ");
  range.min = std::strtod(text.substr(1, comma - 1).c_str(), nullptr);
  range.max = std::strtod(text.substr(comma + 2, text.size() - comma - 3).c_str(), nullptr);
  return range;
}

// The arguments every command needs besides the option under test: its required
// positionals and options, with paths inside `dir`.
std::vector<std::string> RequiredArgs(const CommandPath& command,
                                      const CLI::Option* tested,
                                      const fs::path& dir) {
  std::vector<std::string> args = command.words;
  for (const CLI::Option* o : command.app->get_options()) {
    if (o == tested || !o->get_required()) continue;
    const std::string value = (dir / "out").string();
    if (o->get_positional() && o->nonpositional() == false) {
      args.push_back(value);
    } else {
      args.push_back(o->get_name() + "=" + value);
    }
  }
  return args;
}

struct Outcome {
  bool rejected = false;
  std::string message;
};

// Parses `command` with `--flag=value` (a fresh app, as `arco` would) without running it.
Outcome TryValue(const CommandPath& command_template,
                 const std::string& flag,
                 const std::string& value,
                 const fs::path& dir) {
  App app = BuildApp();
  std::vector<CommandPath> commands;
  CollectCommands(app.app.get(), {}, &commands);
  const auto found = std::find_if(commands.begin(), commands.end(), [&](const CommandPath& c) {
    return c.words == command_template.words;
  });
  const CLI::Option* tested = found->app->get_option(flag);
  std::vector<std::string> args = RequiredArgs(*found, tested, dir);
  args.push_back(flag + "=" + value);
  try {
    app.Parse(args);
  } catch (const CLI::ParseError& e) {
    return {true, e.what()};
  }
  return {false, ""};
}

class AppOptions : public ::testing::Test {
 protected:
  arco::testing::TempDir temp_;
  const fs::path dir_{temp_.path()};
  // Nothing was written: the parse only checks.
  void ExpectNothingWritten() const { EXPECT_TRUE(fs::is_empty(dir_)) << dir_; }
};

// A library message names a field; the CLI names its flag, but not a file's field, a
// path's part or a unit after a number.
TEST(WithFlagNames, NamesTheFlagsOfFieldsButNotFileFieldsPathsOrUnits) {
  constexpr FieldFlag kNames[] = {{"fps", "--fps"}, {"start_s", "--start-s"}};
  EXPECT_EQ(WithFlagNames("fps must be in [1, 1000]", kNames), "--fps must be in [1, 1000]");
  EXPECT_EQ(WithFlagNames("start_s = -1 is before fps", kNames), "--start-s = -1 is before --fps");
  for (const std::string kept : {"right.mp4: 60 fps, but left.mp4 has 30 fps",
                                 "capture.json: \"fps\" must be > 0",
                                 "capture.json: audio.start_s is not a number",
                                 "/data/fps/capture.json: file not found"}) {
    EXPECT_EQ(WithFlagNames(kept, kNames), kept);
  }
}

TEST_F(AppOptions, EveryNumericOptionHasARange) {
  App app = BuildApp();
  std::vector<CommandPath> commands;
  CollectCommands(app.app.get(), {}, &commands);
  ASSERT_GE(commands.size(), 10u);
  int numeric = 0;
  for (const CommandPath& command : commands) {
    for (const CLI::Option* option : command.app->get_options()) {
      if (option->get_type_size_max() == 0 || !IsNumeric(option)) continue;  // flags, text
      ++numeric;
      const std::string where = command.words.back() + " " + option->get_name();
      const CLI::Validator* range = nullptr;
      try {
        range = const_cast<CLI::Option*>(option)->get_validator(kRangeValidatorName);
      } catch (const CLI::OptionNotFound&) {
      }
      EXPECT_NE(range, nullptr) << where
                                << ": a numeric option without a declared range (use AddNumber, "
                                   "cli/number_option.h)";
    }
  }
  EXPECT_GE(numeric, 50) << "the walk found too few numeric options";
}

TEST_F(AppOptions, EveryNumericOptionRejectsBadValuesAtParse) {
  App app = BuildApp();
  std::vector<CommandPath> commands;
  CollectCommands(app.app.get(), {}, &commands);
  int tried = 0;
  for (const CommandPath& command : commands) {
    for (CLI::Option* option : command.app->get_options()) {
      if (option->get_type_size_max() == 0 || !IsNumeric(option)) continue;
      if (option->get_positional() && option->nonpositional() == false) continue;
      const std::string flag = option->get_name();
      const std::string where = command.words.back() + " " + flag;
      CLI::Validator* validator = nullptr;
      try {
        validator = option->get_validator(kRangeValidatorName);
      } catch (const CLI::OptionNotFound&) {
        ADD_FAILURE() << where << ": no declared range";
        continue;
      }
      const NumberRange range = ParseRange(validator->get_description());
      ASSERT_TRUE(std::isfinite(range.min) && std::isfinite(range.max)) << where;
      const double step_min = std::max(1.0, std::abs(range.min));
      const double step_max = std::max(1.0, std::abs(range.max));
      std::vector<std::string> bad = {"nan",
                                      "NaN",
                                      "inf",
                                      "-inf",
                                      "1e300",
                                      "-1e300",
                                      "18446744073709551616",  // 2^64
                                      "abc",
                                      "",
                                      NumberText(range.min_open ? range.min
                                                                  : range.min - step_min),
                                      NumberText(range.max_open ? range.max
                                                                  : range.max + step_max)};
      if (!range.Contains(-1)) bad.push_back("-1");
      for (const std::string& value : bad) {
        const Outcome outcome = TryValue(command, flag, value, dir_);
        ++tried;
        EXPECT_TRUE(outcome.rejected) << where << "=" << value << " was accepted";
        if (!outcome.rejected) continue;
        EXPECT_NE(outcome.message.find(flag), std::string::npos)
            << where << "=" << value << ": the message does not name the flag: "
            << outcome.message;
        EXPECT_EQ(outcome.message.find('\n'), std::string::npos)
            << where << "=" << value << ": more than one line: " << outcome.message;
        if (!value.empty()) {
          EXPECT_NE(outcome.message.find(value), std::string::npos)
              << where << "=" << value << ": the message does not show the value: "
              << outcome.message;
        }
      }
      // The range's own ends and the default are accepted.
      std::vector<std::string> good;
      if (!range.min_open) good.push_back(NumberText(range.min));
      if (!range.max_open) good.push_back(NumberText(range.max));
      std::string defaults = option->get_default_str();
      if (!defaults.empty() && defaults.front() == '[') {  // a list: "[5,10,20]"
        defaults = defaults.substr(1, defaults.size() - 2);
      }
      for (size_t at = 0; !defaults.empty() && at != std::string::npos;) {
        const size_t comma = defaults.find(',', at);
        good.push_back(defaults.substr(at, comma == std::string::npos ? comma : comma - at));
        at = comma == std::string::npos ? comma : comma + 1;
      }
      for (const std::string& value : good) {
        std::string text = value;
        EXPECT_EQ((*validator)(text), "") << where << ": its own range end or default " << value;
      }
    }
  }
  EXPECT_GT(tried, 500);
  ExpectNothingWritten();
}

TEST_F(AppOptions, ReportedExamplesOfTheIssueAreRejected) {
  const std::vector<std::vector<std::string>> cases = {
      {"refine", "r", "--shift-cost", "-100"},
      {"refine", "r", "--normal-weight", "-1"},
      {"refine", "r", "--temporal-weight", "nan"},
      {"pitch", "a.wav", "--fps", "nan"},
      {"pitch", "a.wav", "--fmin", "-10"},
      {"synth", "-o", "s", "--seed", "-1"},
  };
  for (const auto& args : cases) {
    App app = BuildApp();
    try {
      app.Parse(args);
      ADD_FAILURE() << args[0] << " " << args[args.size() - 2] << " " << args.back()
                    << " was accepted";
    } catch (const CLI::ValidationError& e) {
      EXPECT_NE(std::string(e.what()).find(args[args.size() - 2]), std::string::npos) << e.what();
    }
  }
}

TEST_F(AppOptions, ParseCompleteChecksCombinationsBeforeRunning) {
  App app = BuildApp();
  try {
    app.Parse({"pitch", "a.wav", "--fmin", "500", "--fmax", "100"});
    ADD_FAILURE() << "--fmin above --fmax was accepted";
  } catch (const CLI::ValidationError& e) {
    EXPECT_EQ(std::string(e.what()), "--fmin must be below --fmax");
  }
}

TEST_F(AppOptions, GoodValuesParseAndNothingRuns) {
  App app = BuildApp();
  const std::string result = (dir_ / "r").string();
  app.Parse({"refine", result, "--shift-cost", "2.5", "--threads", "3", "--straddle-s", "0"});
  ExpectNothingWritten();
}

// docs/options.md lists every option with its range as the app defines it.
TEST(OptionsMarkdown, DocsPageIsCurrent) {
  const std::string expected = OptionsMarkdown(BuildApp());
  const fs::path page = fs::path(ARCO_SOURCE_DIR) / "docs" / "options.md";
  if (std::getenv("ARCO_WRITE_OPTIONS_DOC") != nullptr) {
    std::FILE* f = std::fopen(page.c_str(), "wb");
    ASSERT_NE(f, nullptr) << page;
    std::fwrite(expected.data(), 1, expected.size(), f);
    std::fclose(f);
  }
  std::string actual;
  if (std::FILE* f = std::fopen(page.c_str(), "rb")) {
    char buffer[4096];
    for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) actual.append(buffer, n);
    std::fclose(f);
  }
  EXPECT_EQ(actual, expected) << page
                              << " is out of date: ARCO_WRITE_OPTIONS_DOC=1 build/tests/cli_app_test "
                                 "--gtest_filter=OptionsMarkdown.* rewrites it";
  EXPECT_NE(expected.find("| `--fps` | FLOAT | (0, 1000] | 30 |"), std::string::npos);
}

TEST(CheckCommandName, NamesAnUnknownCommand) {
  const App app = BuildApp();
  EXPECT_TRUE(CheckCommandName(app, "run").ok());
  EXPECT_TRUE(CheckCommandName(app, "--help").ok());
  const Status unknown = CheckCommandName(app, "frobnicate");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("unknown command 'frobnicate'"), std::string::npos);
}

TEST(CheckCommandNames, NamesAnUnknownSubcommand) {
  const App app = BuildApp();
  EXPECT_TRUE(CheckCommandNames(app, {"capture", "new", "-o", "x"}).ok());
  EXPECT_TRUE(CheckCommandNames(app, {"capture", "--help"}).ok());
  EXPECT_TRUE(CheckCommandNames(app, {"calibration", "show", "x"}).ok());
  EXPECT_TRUE(CheckCommandNames(app, {"run", "frobnicate"}).ok());  // a positional
  const Status unknown = CheckCommandNames(app, {"capture", "frobnicate"});
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.message().find("unknown command 'capture frobnicate'"), std::string::npos)
      << unknown.message();
  EXPECT_NE(unknown.message().find("new, import-keypoints"), std::string::npos)
      << unknown.message();
  const Status bare = CheckCommandNames(app, {"calibration"});
  ASSERT_FALSE(bare.ok());
  EXPECT_NE(bare.message().find("show, convert"), std::string::npos) << bare.message();
  EXPECT_FALSE(CheckCommandNames(app, {"frobnicate", "new"}).ok());
}

}  // namespace
}  // namespace arco::cli
