// The man pages and the bash completion are generated from the same definitions as
// `--help` and docs/options.md: every command has its page, every option is in its page
// and in the completion.
#include "arco/cli/manual.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <map>
#include <string>
#include <vector>

#include "arco/cli/build_info.h"

namespace arco::cli {
namespace {

// How a man page writes text (cli/manual.cc): '-' as "\-".
std::string RoffDashes(const std::string& text) {
  std::string out;
  for (char c : text) out += c == '-' ? std::string("\\-") : std::string(1, c);
  return out;
}

void CollectPaths(const CLI::App& command,
                  const std::string& name,
                  std::map<std::string, const CLI::App*>* out) {
  (*out)[name] = &command;
  for (const CLI::App* sub : command.get_subcommands({})) {
    CollectPaths(*sub, name + "-" + sub->get_name(), out);
  }
}

TEST(Manual, EveryCommandHasAPageWithEveryOption) {
  const App app = BuildApp();
  std::map<std::string, const CLI::App*> commands;
  for (const auto& [sub, run] : app.commands)
    CollectPaths(*sub, "arco-" + sub->get_name(), &commands);
  std::map<std::string, std::string> pages;
  for (const ManPage& page : ManPages(app)) {
    EXPECT_TRUE(pages.emplace(page.name, page.text).second) << page.name << " twice";
  }
  ASSERT_EQ(pages.count("arco"), 1u);
  EXPECT_EQ(pages.size(), commands.size() + 1);
  for (const auto& [name, command] : commands) {
    ASSERT_EQ(pages.count(name), 1u) << name << " has no page";
    const std::string& text = pages[name];
    std::string upper = name;
    for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    EXPECT_NE(text.find(".TH " + RoffDashes(upper) + " 1 "), std::string::npos) << name;
    EXPECT_NE(text.find(".SH NAME\n" + RoffDashes(name) + " \\- "), std::string::npos) << name;
    for (const OptionDoc& o : DocumentedOptions(*command)) {
      for (const std::string& option : o.names) {
        EXPECT_NE(text.find(RoffDashes(option)), std::string::npos) << name << ": " << option;
      }
    }
  }
  // arco(1) lists every command and the global options.
  for (const auto& [sub, run] : app.commands) {
    EXPECT_NE(pages["arco"].find("\\fB" + RoffDashes(sub->get_name()) + "\\fR"), std::string::npos)
        << sub->get_name();
  }
  EXPECT_NE(pages["arco"].find("\\-\\-data\\-dir"), std::string::npos);
  EXPECT_NE(pages["arco"].find("ARCO_DATA_DIR"), std::string::npos);
}

TEST(Manual, PagesAreRoffWithoutStrayRequests) {
  const App app = BuildApp();
  for (const ManPage& page : ManPages(app)) {
    size_t start = 0;
    while (start < page.text.size()) {
      const size_t end = page.text.find('\n', start);
      const std::string line = page.text.substr(start, end - start);
      start = end == std::string::npos ? page.text.size() : end + 1;
      EXPECT_FALSE(line.empty()) << page.name << ": an empty line (a blank line in roff)";
      if (line.empty() || (line[0] != '.' && line[0] != '\'')) continue;
      // Only the requests and macros the generator writes start a line.
      const std::string request = line.substr(0, line.find(' '));
      static const std::vector<std::string> kKnown = {".\\\"", ".TH", ".SH", ".TP", ".PP", ".br"};
      EXPECT_NE(std::find(kKnown.begin(), kKnown.end(), request), kKnown.end())
          << page.name << ": " << line;
    }
  }
}

TEST(Manual, CompletionKnowsCommandsOptionsAndChoices) {
  const App app = BuildApp();
  const std::string script = BashCompletion(app);
  EXPECT_NE(script.find("complete -o default -F _arco arco\n"), std::string::npos);
  for (const auto& [sub, run] : app.commands) {
    EXPECT_NE(script.find("'/" + sub->get_name() + "'"), std::string::npos) << sub->get_name();
    for (const OptionDoc& o : DocumentedOptions(*sub)) {
      if (o.positional) continue;
      for (const std::string& option : o.names) {
        EXPECT_NE(script.find(" " + option), std::string::npos) << sub->get_name() << " " << option;
      }
      if (!o.choices.empty()) {
        EXPECT_NE(script.find("'/" + sub->get_name() + " " + o.names.back() + "')"),
                  std::string::npos)
            << sub->get_name() << " " << o.names.back();
      }
    }
  }
}

TEST(Manual, ChoicesAreReadFromTheDeclaredSet) {
  CLI::App command("test");
  std::string instrument = "none";
  command.add_option("--instrument", instrument, "Instrument")
      ->check(CLI::IsMember({"none", "cello", "violin"}));
  const std::vector<OptionDoc> docs = DocumentedOptions(command);
  ASSERT_EQ(docs.size(), 1u);
  EXPECT_EQ(docs[0].check, "{none,cello,violin}");
  EXPECT_EQ(docs[0].choices, (std::vector<std::string>{"none", "cello", "violin"}));
}

TEST(Manual, TheVersionLineNamesTheRevision) {
  EXPECT_EQ(VersionLine(), std::string("arco ") + Version() + " (git " + SourceRevision() + ")");
  EXPECT_STRNE(SourceRevision(), "");
}

}  // namespace
}  // namespace arco::cli
