#include "aggregator/report/html_table.h"

#include <fmt/format.h>

#include <utility>

#include "shared/io/replace_file.h"
#include "shared/util/check.h"

namespace silnet::aggregator {
namespace {

constexpr const char* kStyle = R"(
body { font-family: sans-serif; margin: 2em; color: #222; max-width: 1500px; }
h1 { font-size: 1.6em; } h2 { font-size: 1.25em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; margin: 0.5em 0; font-size: 0.9em; }
th, td { border: 1px solid #ccc; padding: 3px 8px; text-align: left; vertical-align: top; }
th { background: #f0f0f0; }
tr.bad td { background: #fde8e8; }
tr.warn td { background: #fff6da; }
ul.bad { color: #a00; }
.muted { color: #777; }
img { max-width: 100%; border: 1px solid #ddd; margin: 0.3em 0; }
)";

}  // namespace

std::string Section(const std::string& title, const std::string& body) {
  return "<h2>" + EscapeHtml(title) + "</h2>\n" + body;
}

void WriteHtmlPage(const std::filesystem::path& path, const std::string& title,
                   const std::string& body) {
  ReplaceFile(path, fmt::format("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta "
                                "charset=\"utf-8\">\n<title>{0}</title>\n<style>{1}</style>\n</"
                                "head>\n<body>\n<h1>{0}</h1>\n{2}</body>\n</html>\n",
                                EscapeHtml(title), kStyle, body));
}

std::string EscapeHtml(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

HtmlTable::HtmlTable(std::vector<std::string> header) : header_(std::move(header)) {}

void HtmlTable::AddRow(std::vector<std::string> cells, std::string row_class) {
  rows_.push_back({std::move(cells), std::move(row_class)});
}

std::string HtmlTable::ToHtml(std::string_view empty_message) const {
  if (rows_.empty()) return "<p class=\"muted\">" + EscapeHtml(empty_message) + "</p>\n";
  std::string html = "<table>\n";
  if (!header_.empty()) {
    html += "<tr>";
    for (const std::string& h : header_)
      html += "<th>" + EscapeHtml(h) + "</th>";
    html += "</tr>\n";
  }
  for (const Row& row : rows_) {
    html += row.row_class.empty() ? "<tr>" : "<tr class=\"" + EscapeHtml(row.row_class) + "\">";
    for (const std::string& cell : row.cells)
      html += "<td>" + EscapeHtml(cell) + "</td>";
    html += "</tr>\n";
  }
  return html + "</table>\n";
}

}  // namespace silnet::aggregator
