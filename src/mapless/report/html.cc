#include "mapless/report/html.h"

#include <opencv2/imgcodecs.hpp>

#include "mapless/core/check.h"
#include "mapless/io/lazy_libraries.h"
#include "mapless/report/svg.h"

namespace mapless::report {
namespace {

std::string Base64(const std::vector<unsigned char>& bytes) {
  static const char kTable[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += kTable[(v >> 6) & 63];
    out += kTable[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v = (bytes[i] << 16) | (two ? bytes[i + 1] << 8 : 0);
    out += kTable[(v >> 18) & 63];
    out += kTable[(v >> 12) & 63];
    out += two ? kTable[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

constexpr char kStyle[] = R"(
body{font-family:sans-serif;margin:24px auto;max-width:1100px;color:#222;line-height:1.4}
h1{font-size:1.6em;margin-bottom:0.2em}h2{font-size:1.3em;margin-top:1.6em;border-bottom:1px solid #ddd}
h3{font-size:1.1em;margin-top:1.2em}
.byline{color:#555;font-size:0.9em;margin-top:0;font-family:monospace}
table{border-collapse:collapse;margin:0.6em 0;font-size:0.92em}
th,td{border:1px solid #ccc;padding:3px 8px}th{background:#f2f2f2}td.n{text-align:right}
figure{margin:0.8em 0;display:inline-block;vertical-align:top}
figcaption{font-size:0.85em;color:#555;max-width:640px}
.row{display:flex;flex-wrap:wrap;gap:10px;align-items:flex-start}
.row img{image-rendering:pixelated;border:1px solid #ccc}
)";

bool LooksNumeric(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!(std::isdigit(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+' ||
          c == '/' || c == '%' || c == ' ' || c == 'e'))
      return false;
  return true;
}

}  // namespace

std::string PngDataUri(const cv::Mat& image) {
  std::vector<unsigned char> png;
  if (image.empty() || !io::lazy::ImEncode(".png", image, &png, {}))
    throw InputError("report: an image could not be encoded as PNG");
  return "data:image/png;base64," + Base64(png);
}

HtmlReport::HtmlReport(std::string title) : title_(std::move(title)) {}

void HtmlReport::Heading(const std::string& text, int level, const std::string& id) {
  const std::string h = "h" + std::to_string(std::clamp(level, 1, 4));
  body_ += "<" + h + (id.empty() ? "" : " id=\"" + Escape(id) + "\"") + ">" + Escape(text) + "</" +
           h + ">\n";
}

void HtmlReport::Paragraph(const std::string& text) { body_ += "<p>" + Escape(text) + "</p>\n"; }

void HtmlReport::Table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows) {
  body_ += "<table>\n<tr>";
  for (const std::string& h : header) body_ += "<th>" + Escape(h) + "</th>";
  body_ += "</tr>\n";
  for (const auto& row : rows) {
    body_ += "<tr>";
    for (const std::string& cell : row)
      body_ += (LooksNumeric(cell) ? "<td class=\"n\">" : "<td>") + Escape(cell) + "</td>";
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::Figure(const std::string& svg, const std::string& caption) {
  body_ += "<figure>\n" + svg + "<figcaption>" + Escape(caption) + "</figcaption></figure>\n";
}

void HtmlReport::Images(const std::vector<std::pair<cv::Mat, std::string>>& images,
                        const std::string& caption) {
  body_ += "<div class=\"row\">\n";
  for (const auto& [image, text] : images) {
    body_ += "<figure><img alt=\"" + Escape(text) + "\" width=\"" + std::to_string(image.cols) +
             "\" height=\"" + std::to_string(image.rows) + "\" src=\"" + PngDataUri(image) +
             "\"><figcaption>" + Escape(text) + "</figcaption></figure>\n";
  }
  body_ += "</div>\n";
  if (!caption.empty()) body_ += "<p><small>" + Escape(caption) + "</small></p>\n";
}

std::string HtmlReport::Html() const {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta "
         "name=\"generator\" "
         "content=\"mapless\">\n<link "
         "rel=\"icon\" href=\"data:,\">\n<title>" +
         Escape(title_) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n<h1>" +
         Escape(title_) + "</h1>\n" +
         (byline_.empty() ? "" : "<p class=\"byline\">" + Escape(byline_) + "</p>\n") + body_ +
         "</body>\n</html>\n";
}

}  // namespace mapless::report
