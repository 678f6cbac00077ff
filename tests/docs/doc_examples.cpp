#include "tests/docs/doc_examples.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

namespace rastray::test::docs {
namespace fs = std::filesystem;

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

bool startsWith(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

std::vector<std::string> splitWords(const std::string& s) {
  std::vector<std::string> words;
  std::istringstream in(s);
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The comment of a command line: after " #" outside quotes (URLs and
// `--vary` values hold no " #").
void splitComment(const std::string& line, std::string* command, std::string* comment) {
  const auto hash = line.find(" #");
  *command = trim(line.substr(0, hash));
  *comment = hash == std::string::npos ? "" : trim(line.substr(hash + 2));
}

// Reads the `;`-separated clauses of a command's comment; anything else in
// the comment is prose for the reader.
void readClauses(const std::string& comment, Command* c, std::string* error) {
  std::istringstream in(comment);
  for (std::string clause; std::getline(in, clause, ';');) {
    clause = trim(clause);
    if (startsWith(clause, "exits ")) {
      try {
        c->expected_status = std::stoi(clause.substr(6));
      } catch (...) {
        *error = "line " + std::to_string(c->line_number) + ": `exits` needs a number: " + clause;
      }
    } else if (startsWith(clause, "writes ")) {
      for (const std::string& w : splitWords(clause.substr(7))) c->writes.push_back(w);
    } else if (startsWith(clause, "slow, tested with ")) {
      c->tested_with = trim(clause.substr(18));
    }
  }
}

}  // namespace

std::string Block::name() const {
  std::string n = file + "_L" + std::to_string(line_number);
  for (char& ch : n)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return n;
}

void PrintTo(const Block& block, std::ostream* os) { *os << block.file << ":" << block.line_number; }

std::vector<Block> parseMarkdown(const std::string& text, const std::string& relative) {
  std::vector<Block> blocks;
  std::istringstream in(text);
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);

  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string fence = trim(lines[i]);
    if (!startsWith(fence, "```") || fence == "```") continue;
    const std::string info = trim(fence.substr(3));
    size_t end = i + 1;
    while (end < lines.size() && trim(lines[end]) != "```") ++end;
    std::vector<std::string> body(lines.begin() + i + 1, lines.begin() + std::min(end, lines.size()));
    const int first = static_cast<int>(i) + 1;
    i = end;

    if (info == "text") {
      // Sample output of the last ```sh block before it in this file.
      if (blocks.empty()) {
        Block orphan;
        orphan.file = relative;
        orphan.line_number = first;
        orphan.error = "a ```text block with no ```sh example before it";
        blocks.push_back(orphan);
      } else {
        blocks.back().sample.insert(blocks.back().sample.end(), body.begin(), body.end());
      }
      continue;
    }
    if (info != "sh" && !startsWith(info, "sh ")) continue;

    Block b;
    b.file = relative;
    b.line_number = first;
    const std::string marker = trim(info.substr(2));
    if (marker.empty()) {
      b.kind = BlockKind::Run;
    } else if (marker == "serve") {
      b.kind = BlockKind::Serve;
    } else if (startsWith(marker, "serve pending:")) {
      b.kind = BlockKind::Serve;
      b.pending = true;
      b.reason = trim(marker.substr(14));
      if (b.reason.empty()) b.error = "a pending block must say why";
    } else if (marker == "ci") {
      b.kind = BlockKind::Ci;
    } else if (startsWith(marker, "not-run:")) {
      b.kind = BlockKind::NotRun;
      b.reason = trim(marker.substr(8));
    } else if (startsWith(marker, "pending:")) {
      b.kind = BlockKind::Pending;
      b.reason = trim(marker.substr(8));
    } else {
      b.error = "unknown marker ```sh " + marker;
    }
    if ((b.kind == BlockKind::NotRun || b.kind == BlockKind::Pending) && b.reason.empty())
      b.error = "a not-run or pending block must say why";

    for (size_t k = 0; k < body.size(); ++k) {
      std::string joined = body[k];
      const int number = first + 1 + static_cast<int>(k);
      while (!joined.empty() && joined.back() == '\\' && k + 1 < body.size()) {
        joined.pop_back();
        joined = trim(joined) + " " + trim(body[++k]);
      }
      joined = trim(joined);
      if (joined.empty() || joined[0] == '#') continue;
      Command c;
      c.line_number = number;
      std::string comment;
      splitComment(joined, &c.line, &comment);
      readClauses(comment, &c, &b.error);
      const bool rastray = startsWith(c.line, "rastray ") || startsWith(c.line, "./build/rastray ");
      const bool curl = b.kind == BlockKind::Serve && !b.commands.empty() && startsWith(c.line, "curl ");
      if (b.kind != BlockKind::Ci && b.kind != BlockKind::NotRun && !rastray && !curl)
        b.error = "line " + std::to_string(number) +
                  ": not a rastray command (mark the block `sh not-run: WHY`): " + c.line;
      b.commands.push_back(c);
    }
    if (b.commands.empty() && b.error.empty()) b.error = "an example block without a command";
    if (b.kind == BlockKind::Serve && b.error.empty() && !startsWith(b.commands[0].line, "rastray serve") &&
        !startsWith(b.commands[0].line, "./build/rastray serve"))
      b.error = "a `sh serve` block starts with `rastray serve`";
    blocks.push_back(b);
  }
  return blocks;
}

std::vector<Block> loadBlocks(const std::string& source_dir) {
  std::vector<std::string> files = {"README.md"};
  std::vector<std::string> pages;
  for (const auto& entry : fs::directory_iterator(fs::path(source_dir) / "docs"))
    if (entry.path().extension() == ".md") pages.push_back("docs/" + entry.path().filename().string());
  std::sort(pages.begin(), pages.end());
  files.insert(files.end(), pages.begin(), pages.end());

  std::vector<Block> all;
  for (const std::string& f : files) {
    std::ifstream in(fs::path(source_dir) / f);
    std::stringstream text;
    text << in.rdbuf();
    for (Block& b : parseMarkdown(text.str(), f)) all.push_back(std::move(b));
  }
  return all;
}

std::string applyOverrides(const std::string& line, const std::string& tested_with) {
  std::vector<std::string> words = splitWords(line);
  const std::vector<std::string> with = splitWords(tested_with);
  for (size_t i = 0; i < with.size();) {
    size_t j = i + 1;
    while (j < with.size() && !startsWith(with[j], "--")) ++j;
    const std::vector<std::string> option(with.begin() + i, with.begin() + j);
    auto at = std::find(words.begin(), words.end(), option[0]);
    if (at == words.end()) {
      words.insert(words.end(), option.begin(), option.end());
    } else {
      // Replace the option and as many following values as the override has.
      auto last = at + 1;
      while (last != words.end() && !startsWith(*last, "--") &&
             static_cast<size_t>(last - at) < option.size())
        ++last;
      at = words.erase(at, last);
      words.insert(at, option.begin(), option.end());
    }
    i = j;
  }
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : " ") + w;
  return out;
}

std::string normalise(const std::string& line) {
  // Numbers: integers, decimals, exponents, digit groups (76,800).
  static const std::regex number(R"([-+]?(\d[\d,]*(\.\d*)?|\.\d+)([eE][-+]?\d+)?)");
  static const std::regex blanks(R"([ \t]+)");
  return trim(std::regex_replace(std::regex_replace(line, number, "#"), blanks, " "));
}

bool matchesSample(const std::vector<std::string>& sample, const std::string& out, const std::string& err,
                   std::string* missing) {
  auto linesOf = [](const std::string& s) {
    std::vector<std::string> v;
    std::istringstream in(s);
    for (std::string l; std::getline(in, l);) v.push_back(normalise(l));
    return v;
  };
  const std::vector<std::string> outs = linesOf(out), errs = linesOf(err);
  size_t at_out = 0, at_err = 0;
  for (const std::string& raw : sample) {
    std::string want = normalise(raw);
    if (startsWith(want, "$ ")) continue;  // a prompt line echoes the command
    if (want.empty() || want == "...") continue;
    auto o = std::find(outs.begin() + at_out, outs.end(), want);
    if (o != outs.end()) {
      at_out = static_cast<size_t>(o - outs.begin()) + 1;
      continue;
    }
    auto e = std::find(errs.begin() + at_err, errs.end(), want);
    if (e != errs.end()) {
      at_err = static_cast<size_t>(e - errs.begin()) + 1;
      continue;
    }
    *missing = raw;
    return false;
  }
  return true;
}

}  // namespace rastray::test::docs
