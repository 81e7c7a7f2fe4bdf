#pragma once
// Minimal HTML building for the reports: escaping and tables whose cells are escaped text.

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace silnet::aggregator {

// `text` with &, <, >, " and ' replaced by character references.
std::string EscapeHtml(std::string_view text);

// "<h2>title</h2>" (escaped) followed by `body` (HTML).
std::string Section(const std::string& title, const std::string& body);

// Writes a self-contained page: the reports' style sheet, <h1>`title`</h1> and `body`
// (HTML), replacing `path` at once (a browser reloading it never reads half a page). Throws
// InputError naming the path if it cannot be written.
void WriteHtmlPage(const std::filesystem::path& path, const std::string& title,
                   const std::string& body);

// A table built row by row. Cells are plain text (escaped when written); a row may carry a
// CSS class (e.g. "bad" for unplaced cameras or rejected edges).
class HtmlTable {
 public:
  // An empty `header` gives a table without a header row.
  explicit HtmlTable(std::vector<std::string> header);

  void AddRow(std::vector<std::string> cells, std::string row_class = {});
  bool empty() const { return rows_.empty(); }

  // The <table> element; `empty_message` replaces it when there are no rows.
  std::string ToHtml(std::string_view empty_message = "none") const;

 private:
  struct Row {
    std::vector<std::string> cells;
    std::string row_class;
  };
  std::vector<std::string> header_;
  std::vector<Row> rows_;
};

}  // namespace silnet::aggregator
