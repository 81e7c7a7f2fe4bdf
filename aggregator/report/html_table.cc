#include "aggregator/report/html_table.h"

#include <utility>

namespace silnet::aggregator {

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
