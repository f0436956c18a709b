// robomill_docgen: the generated pages of docs/ (`make docs`) and their
// staleness checks (ctest).
//
//   robomill_docgen job-reference [--output FILE] [--check FILE]
//       docs/job-reference.md from the job schema (src/job/job_schema_table.cpp).
//   robomill_docgen validation-report --records LOG [--output FILE] [--check FILE]
//       docs/validation-report.md from the records the validation tests
//       appended to LOG (tests/support/validation_record.hpp).
//   robomill_docgen theory --check docs/theory.md --source SOURCE_DIR
//       every row of docs/theory.md's equation map (one table per paper,
//       000-004) is well formed, and every function it names exists in a
//       file under include/ or src/ named on the same row.
//
// --check compares with the committed page and fails with "… is stale; run
// `make docs`". For the validation report a partial run (`ctest -R …`, so
// only some recording tests ran) cannot regenerate the whole page: its rows
// are checked against the committed page and the test is skipped (exit 77)
// when they all match.

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "robomill/job/job_schema.hpp"

namespace {

constexpr int kSkip = 77;

std::string read_file(const std::string& path, bool& ok) {
  std::ifstream in(path, std::ios::binary);
  ok = static_cast<bool>(in);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

bool write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  return static_cast<bool>(out);
}

/// The first line where `a` and `b` differ, for the stale message.
std::string first_difference(const std::string& committed, const std::string& generated) {
  std::istringstream a(committed), b(generated);
  std::string la, lb;
  for (int line = 1;; ++line) {
    const bool ha = static_cast<bool>(std::getline(a, la));
    const bool hb = static_cast<bool>(std::getline(b, lb));
    if (!ha && !hb)
      return "";
    if (!ha || !hb || la != lb) {
      return fmt::format("first difference at line {}:\n  committed: {}\n  generated: {}", line,
                         ha ? la : "(end of file)", hb ? lb : "(end of file)");
    }
  }
}

int stale(const std::string& page, const std::string& committed, const std::string& generated) {
  std::cerr << page << " is stale; run `make docs`\n"
            << first_difference(committed, generated) << "\n";
  return 1;
}

std::string escape_cell(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  return out.empty() ? "—" : out;
}

struct Record {
  nlohmann::json json;
  std::string test, file, paper;
  std::size_t order = 0;
};

const std::map<std::string, std::string> kPapers = {
    {"000", "Chatter stability of robot milling with force-induced deformation (KR600)"},
    {"001", "Surface topography in robotic ball-end milling with tool vibration"},
    {"002", "Reduced elasto-dynamic model of robotic milling (KR270)"},
    {"003", "Process damping in robotic milling (KR270)"},
    {"004", "Workpiece pose optimization for flexible-joint robots (KR300)"},
};

/// Sections that compare robomill with itself rather than with a paper: the
/// record's "paper" key, the heading, and the name of the reference column.
struct CrossCheck {
  const char* heading;
  const char* reference;
};
const std::map<std::string, CrossCheck> kCrossChecks = {
    {"sim",
     {"Time-domain simulation against the frequency-domain boundary (issue 20)", "stability"}},
    {"listen",
     {"Chatter heard in simulated recordings: listen against simulate (issue 22)", "simulate"}},
    {"listen-recordings",
     {"Chatter heard in real recordings: listen against the dataset's labels (issue 22)", "label"}},
};

std::string row_of(const nlohmann::json& r) {
  auto s = [&](const char* key) { return escape_cell(r.value(key, std::string())); };
  return "| " + s("item") + " | " + s("quantity") + " | " + s("unit") + " | " + s("paper_value") +
         " | " + s("ours") + " | " + s("error") + " | " + s("tolerance") + " | " +
         (r.value("passed", false) ? "yes" : "**no**") + " | " + s("assumptions") + " |";
}

struct Report {
  std::string text;
  std::vector<std::string> rows;  ///< the data rows, for partial checks
  std::set<std::string> tests;
};

Report validation_report(const std::vector<Record>& input) {
  std::vector<Record> records = input;
  std::stable_sort(records.begin(), records.end(), [](const Record& a, const Record& b) {
    return std::tie(a.paper, a.file, a.test, a.order) < std::tie(b.paper, b.file, b.test, b.order);
  });
  Report report;
  std::map<std::string, std::pair<std::string, int>> tests;  // test → file, records
  int passed = 0;
  for (const Record& r : records) {
    auto& t = tests[r.test];
    t.first = r.file;
    ++t.second;
    passed += r.json.value("passed", false);
  }
  std::string& out = report.text;
  out += R"(# Validation report

<!-- Generated by the validation tests (tests/support/validation_record.hpp)
     and robomill_docgen; do not edit. `make docs` regenerates it; `make test`
     fails when it differs from what the tests record. -->

Every row is one comparison a validation test makes against a paper's
published value, recorded next to the test's own assertion with the same
tolerance: the paper's value, ours (4 significant digits), the error, the
tolerance the test accepts, whether it passed, and what the comparison
assumes. The last section compares robomill with itself: the time-domain
simulation's chatter verdict against the frequency-domain boundary, point by
point. The discussion of each comparison is in
[validation.md](validation.md); the modelling choices in
[assumptions.md](assumptions.md).

)";
  out +=
      fmt::format("{} comparisons from {} tests; {} pass.\n", records.size(), tests.size(), passed);
  std::string paper;
  for (const Record& r : records) {
    if (r.paper != paper) {
      paper = r.paper;
      const auto title = kPapers.find(paper);
      const auto check = kCrossChecks.find(paper);
      if (check != kCrossChecks.end())
        out += std::string("\n## ") + check->second.heading + "\n\n| item | quantity | unit | " +
               check->second.reference + " | ours | error | tolerance | pass | assumptions |\n";
      else
        out += "\n## Paper " + paper +
               (title != kPapers.end() ? " — " + title->second : std::string()) +
               "\n\n| item | quantity | unit | paper | ours | error | tolerance | pass | "
               "assumptions |\n";
      out += "|---|---|---|---|---|---|---|---|---|\n";
    }
    const std::string row = row_of(r.json);
    out += row + "\n";
    report.rows.push_back(row);
  }
  out += "\n## Recording tests\n\n| test | file | comparisons |\n|---|---|---|\n";
  for (const auto& [name, t] : tests) {
    out += fmt::format("| `{}` | `{}` | {} |\n", name, t.first, t.second);
    report.tests.insert(name);
  }
  return report;
}

/// The test names listed in a committed report's "Recording tests" table.
std::set<std::string> listed_tests(const std::string& page) {
  std::set<std::string> names;
  const auto at = page.find("## Recording tests");
  if (at == std::string::npos)
    return names;
  std::istringstream lines(page.substr(at));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("| `", 0) != 0)
      continue;
    const auto end = line.find('`', 3);
    if (end != std::string::npos)
      names.insert(line.substr(3, end - 3));
  }
  return names;
}

/// The backquoted words of a Markdown table cell.
std::vector<std::string> backquoted(const std::string& cell) {
  std::vector<std::string> words;
  std::size_t at = 0;
  while ((at = cell.find('`', at)) != std::string::npos) {
    const std::size_t end = cell.find('`', at + 1);
    if (end == std::string::npos)
      break;
    words.push_back(cell.substr(at + 1, end - at - 1));
    at = end + 1;
  }
  return words;
}

/// docs/theory.md's equation map, one table per paper ("### Paper 000" …
/// "### Paper 004"): every row must have four cells and name at least one
/// function and one file; every file must lie under include/ or src/ and
/// exist; every function must occur in one of the files named on the same
/// row (the name after the last "::", as a whole word). A malformed row, a
/// row outside a paper's table or a paper without rows fails the check.
int check_theory(const std::string& page_path, const std::string& source_dir) {
  bool ok = false;
  const std::string page = read_file(page_path, ok);
  const auto begin = page.find("## Equation map");
  if (!ok || begin == std::string::npos) {
    std::cerr << page_path << ": no \"## Equation map\" section\n";
    return 1;
  }
  const auto end = page.find("\n## ", begin + 1);
  std::istringstream lines(page.substr(begin, end - begin));
  std::string line, paper;
  std::map<std::string, int> rows_of = {{"000", 0}, {"001", 0}, {"002", 0}, {"003", 0}, {"004", 0}};
  int rows = 0, names = 0, missing = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("### Paper ", 0) == 0) {
      paper = line.substr(10);
      continue;
    }
    if (line.rfind("|", 0) != 0 || line.rfind("| equation", 0) == 0 ||
        line.find_first_not_of("|-: ") == std::string::npos)
      continue;  // not a table row, a header or a separator
    std::vector<std::string> cells;
    std::size_t at = 1;
    for (std::size_t bar; (bar = line.find(" |", at)) != std::string::npos; at = bar + 2)
      cells.push_back(line.substr(at, bar - at));
    const std::vector<std::string> files =
        cells.size() == 4 ? backquoted(cells[3]) : std::vector<std::string>();
    const std::vector<std::string> functions =
        cells.size() == 4 ? backquoted(cells[2]) : std::vector<std::string>();
    if (line.rfind("| ", 0) != 0 || cells.size() != 4 || at != line.size() || files.empty() ||
        functions.empty() || rows_of.count(paper) == 0) {
      std::cerr << page_path << ": not a row of a paper's table (four cells: equation, what it "
                << "is, `function`s, `file`s): " << line << "\n";
      ++missing;
      continue;
    }
    ++rows;
    ++rows_of[paper];
    std::string sources;
    for (const std::string& file : files) {
      bool read = false;
      if (file.rfind("include/", 0) == 0 || file.rfind("src/", 0) == 0)
        sources += read_file(source_dir + "/" + file, read);
      if (!read) {
        std::cerr << page_path << ": '" << file
                  << "' is not a file under include/ or src/; update the equation map\n";
        ++missing;
      }
    }
    for (const std::string& name : functions) {
      ++names;
      const std::string word =
          name.substr(name.rfind(':') == std::string::npos ? 0 : name.rfind(':') + 1);
      bool found = false;
      for (std::size_t pos = 0; !found && (pos = sources.find(word, pos)) != std::string::npos;
           ++pos) {
        auto is_word = [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
        };
        const bool left = pos == 0 || !is_word(sources[pos - 1]);
        const bool right =
            pos + word.size() >= sources.size() || !is_word(sources[pos + word.size()]);
        found = left && right;
      }
      if (!found) {
        std::cerr << page_path << ": " << name << " is not in " << cells[3]
                  << "; update the equation map\n";
        ++missing;
      }
    }
  }
  for (const auto& [number, count] : rows_of)
    if (count == 0) {
      std::cerr << page_path << ": no rows for paper " << number << " (\"### Paper " << number
                << "\")\n";
      ++missing;
    }
  if (missing > 0 || rows == 0)
    return 1;
  std::cout << page_path << ": " << names << " functions on " << rows
            << " rows of the equation map (papers 000-004), all found\n";
  return 0;
}

struct Arguments {
  std::string command, records, output, check, source;
};

int usage() {
  std::cerr << "usage: robomill_docgen job-reference [--output FILE] [--check FILE]\n"
               "       robomill_docgen validation-report --records LOG [--output FILE] "
               "[--check FILE]\n"
               "       robomill_docgen theory --check docs/theory.md --source SOURCE_DIR\n";
  return 2;
}

int job_reference(const Arguments& args) {
  const std::string page = robomill::job::schema::markdown();
  if (!args.output.empty() && !write_file(args.output, page)) {
    std::cerr << "cannot write " << args.output << "\n";
    return 1;
  }
  if (args.output.empty() && args.check.empty())
    std::cout << page;
  if (!args.check.empty()) {
    bool ok = false;
    const std::string committed = read_file(args.check, ok);
    if (!ok || committed != page)
      return stale("docs/job-reference.md", committed, page);
    std::cout << "docs/job-reference.md is up to date (" << robomill::job::schema::fields().size()
              << " fields)\n";
  }
  return 0;
}

int validation(const Arguments& args) {
  std::vector<Record> records;
  bool ok = false;
  const std::string log = read_file(args.records, ok);
  std::istringstream lines(log);
  std::string line;
  std::size_t order = 0;
  while (std::getline(lines, line)) {
    if (line.empty())
      continue;
    Record r;
    try {
      r.json = nlohmann::json::parse(line);
    } catch (const nlohmann::json::exception& e) {
      std::cerr << args.records << ": unreadable record: " << e.what() << "\n";
      return 1;
    }
    r.test = r.json.value("test", "");
    r.file = r.json.value("file", "");
    r.paper = r.json.value("paper", "");
    r.order = order++;
    records.push_back(std::move(r));
  }
  const Report report = validation_report(records);
  if (!args.output.empty() && !write_file(args.output, report.text)) {
    std::cerr << "cannot write " << args.output << "\n";
    return 1;
  }
  if (args.output.empty() && args.check.empty())
    std::cout << report.text;
  if (args.check.empty())
    return 0;
  const std::string committed = read_file(args.check, ok);
  if (ok && committed == report.text) {
    std::cout << "docs/validation-report.md is up to date (" << records.size()
              << " comparisons from " << report.tests.size() << " tests)\n";
    return 0;
  }
  // A partial run: fewer recording tests than the committed page lists, and
  // none that it does not.
  const std::set<std::string> listed = listed_tests(committed);
  const bool subset =
      std::includes(listed.begin(), listed.end(), report.tests.begin(), report.tests.end());
  if (ok && subset && report.tests.size() < listed.size()) {
    for (const std::string& row : report.rows) {
      if (committed.find(row + "\n") == std::string::npos) {
        std::cerr << "docs/validation-report.md is stale; run `make docs`\n"
                  << "this run recorded a row the committed report does not have:\n  " << row
                  << "\n";
        return 1;
      }
    }
    std::cout << "partial run: " << report.tests.size() << " of " << listed.size()
              << " recording tests ran and their " << records.size()
              << " rows match docs/validation-report.md; the whole report is checked when all "
                 "tests run\n";
    return kSkip;
  }
  return stale("docs/validation-report.md", committed, report.text);
}

}  // namespace

int main(int argc, char** argv) {
  Arguments args;
  if (argc < 2)
    return usage();
  args.command = argv[1];
  for (int i = 2; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i + 1 >= argc)
      return usage();
    const std::string value = argv[++i];
    if (flag == "--output")
      args.output = value;
    else if (flag == "--check")
      args.check = value;
    else if (flag == "--records")
      args.records = value;
    else if (flag == "--source")
      args.source = value;
    else
      return usage();
  }
  try {
    if (args.command == "job-reference")
      return job_reference(args);
    if (args.command == "validation-report" && !args.records.empty())
      return validation(args);
    if (args.command == "theory" && !args.check.empty() && !args.source.empty())
      return check_theory(args.check, args.source);
  } catch (const std::exception& e) {
    std::cerr << "robomill_docgen: " << e.what() << "\n";
    return 1;
  }
  return usage();
}
