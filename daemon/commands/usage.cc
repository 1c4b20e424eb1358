#include "daemon/commands/usage.h"

#include <algorithm>
#include <iostream>
#include <memory>
#include <sstream>

#include "daemon/commands/commands.h"

namespace pvtwin::cli {

namespace {

// The top-level help lists each verb on one line: its summary.
class VerbListFormatter : public CLI::Formatter {
 public:
  std::string make_subcommand(const CLI::App* sub) const override {
    std::string summary = VerbSummary(sub->get_name());
    if (summary.empty())
      summary = sub->get_description().substr(0, sub->get_description().find('\n'));
    std::stringstream out;
    CLI::detail::format_help(out, sub->get_name(), summary, get_column_width());
    return out.str();
  }
};

std::vector<std::string> VerbNames(const CLI::App& app) {
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    names.push_back(sub->get_name());
  }
  return names;
}

// Long option names (with their dashes) of `app`; the hidden ones (group "")
// only when `hidden` is set.
std::vector<std::string> LongOptionNames(const CLI::App& app, bool hidden) {
  std::vector<std::string> names;
  for (const CLI::Option* opt : app.get_options()) {
    if (!hidden && opt->get_group().empty()) continue;
    for (const std::string& n : opt->get_lnames()) names.push_back("--" + n);
  }
  return names;
}

std::string Suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  const std::optional<std::string> near = NearestMatch(word, candidates);
  return near ? "; did you mean " + *near + "?" : "";
}

// Unknown verb or unknown long option: the message, or "" when there is none.
std::string UnknownWord(const CLI::App& app, const std::vector<std::string>& args) {
  const std::vector<std::string> top_options = LongOptionNames(app, true);
  std::size_t i = 0;
  for (; i < args.size() && args[i].rfind("-", 0) == 0; ++i) {
    const std::string name = args[i].substr(0, args[i].find('='));
    if (name.rfind("--", 0) == 0 &&
        std::find(top_options.begin(), top_options.end(), name) == top_options.end()) {
      return "unknown option " + name + Suggestion(name, LongOptionNames(app, false));
    }
  }
  if (i == args.size()) return "";
  const std::string& verb = args[i];
  const std::vector<std::string> verbs = VerbNames(app);
  if (std::find(verbs.begin(), verbs.end(), verb) == verbs.end()) {
    const std::optional<std::string> near = NearestMatch(verb, verbs);
    return "unknown command " + verb +
           (near ? "; did you mean " + *near + "?"
                 : "; run `pvtwin help` for the list of commands");
  }
  const CLI::App* sub = app.get_subcommand(verb);
  const std::vector<std::string> known = LongOptionNames(*sub, true);
  for (++i; i < args.size() && args[i] != "--"; ++i) {
    if (args[i].rfind("--", 0) != 0) continue;
    const std::string name = args[i].substr(0, args[i].find('='));
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      return "unknown option " + name + " of `pvtwin " + verb + "`" +
             Suggestion(name, LongOptionNames(*sub, false));
    }
  }
  return "";
}

// Every required option of the chosen verb that the command line lacks.
std::string MissingRequired(CLI::App& app) {
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  if (chosen.empty()) return "a command is required; run `pvtwin help` for the list of commands";
  std::string missing;
  for (const CLI::Option* opt : chosen.front()->get_options()) {
    if (opt->get_required() && opt->count() == 0) {
      missing += (missing.empty() ? "" : ", ") + opt->get_name();
    }
  }
  if (missing.empty()) return "";
  const std::string verb = chosen.front()->get_name();
  return "`pvtwin " + verb + "` is missing " + missing + "; run `pvtwin help " + verb +
         "` for its options";
}

}  // namespace

std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::optional<std::string> NearestMatch(const std::string& word,
                                        const std::vector<std::string>& candidates) {
  std::optional<std::string> best;
  std::size_t best_distance = 0;
  for (const std::string& c : candidates) {
    const bool prefix = word.size() >= 3 && (c.rfind(word, 0) == 0 || word.rfind(c, 0) == 0);
    const std::size_t d = EditDistance(word, c);
    if (d > 2 && !prefix) continue;
    if (!best || d < best_distance) {
      best = c;
      best_distance = d;
    }
  }
  return best;
}

std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv) {
  app.formatter(std::make_shared<VerbListFormatter>());
  app.footer(
      "\nRun `pvtwin help VERB` (or `pvtwin VERB --help`) for a verb's options and an "
      "example.");
  std::vector<std::string> args(argv + 1, argv + argc);
  // `pvtwin help [VERB]` is `pvtwin [VERB] --help`.
  if (!args.empty() && args.front() == "help") {
    args.erase(args.begin());
    args.resize(std::min<std::size_t>(args.size(), 1));
    args.push_back("--help");
  }
  if (const std::string unknown = UnknownWord(app, args); !unknown.empty()) {
    std::cerr << "pvtwin: " << unknown << "\n";
    return kExitBadInput;
  }
  // CLI11 parses a reversed vector of the arguments.
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  app.name(argc > 0 ? argv[0] : "pvtwin");
  try {
    app.parse(reversed);
  } catch (const CLI::RequiredError& e) {
    if (const std::string missing = MissingRequired(app); !missing.empty()) {
      std::cerr << "pvtwin: " << missing << "\n";
      return kExitBadInput;
    }
    return app.exit(e) == 0 ? kExitOk : kExitBadInput;
  } catch (const CLI::ParseError& e) {
    // CLI11 uses exit code 0 for --help; bad usage is bad input (2).
    return app.exit(e) == 0 ? kExitOk : kExitBadInput;
  }
  return std::nullopt;
}

}  // namespace pvtwin::cli
