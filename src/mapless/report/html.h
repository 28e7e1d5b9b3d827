// A self-contained HTML report: headings, text, tables, inline SVG figures and images embedded as
// PNG data URIs. No scripts, fonts, style sheets or links outside the file: it opens offline and
// can be mailed or attached to an issue as one file. Pure: Html() returns the text; the caller
// writes it (atomically).
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace mapless::report {

class HtmlReport {
 public:
  explicit HtmlReport(std::string title);

  // A line under the title: which mapless, when and how the report was made (plain text).
  void Byline(const std::string& text) { byline_ = text; }
  void Heading(const std::string& text, int level = 2, const std::string& id = "");
  void Paragraph(const std::string& text);  // plain text (escaped)
  // A table; cells are plain text. `align_right`: numbers (every column but the first).
  void Table(const std::vector<std::string>& header,
             const std::vector<std::vector<std::string>>& rows);
  void Figure(const std::string& svg, const std::string& caption);
  // Images side by side (grey or BGR), each with its caption, embedded as PNG.
  void Images(const std::vector<std::pair<cv::Mat, std::string>>& images,
              const std::string& caption = "");

  std::string Html() const;

 private:
  std::string title_;
  std::string byline_;
  std::string body_;
};

// "data:image/png;base64,..." of an image (grey or BGR).
std::string PngDataUri(const cv::Mat& image);

}  // namespace mapless::report
