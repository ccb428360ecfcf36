#pragma once
// One self-contained HTML report per session: tables, and plots rendered by gnuplot (Debian
// gnuplot-nox) from data files + scripts written next to the report (plots/), embedded as base64
// PNG data URIs so that the HTML file alone is the report. The .dat/.gp files stay for people who
// want to re-plot. Without gnuplot the report says so where a plot would be (nothing else fails).

#include <string>
#include <vector>

#include "viewline/tuning/scenario.h"

namespace viewline::tuning {

/// One HTML report built section by section, with its plots embedded.
class HtmlReport {
public:
  /// A report titled `title`; plots go to the folder plots under `dir`.
  HtmlReport(std::string title, std::string dir);

  /// A heading of this level (h2 by default); `text` is escaped.
  void heading(const std::string& text, int level = 2);
  /// A paragraph of HTML (the caller escapes its text).
  void paragraph(const std::string& html);
  /// A preformatted block of plain text (escaped).
  void preformatted(const std::string& text);
  /// A table of text cells (escaped); `row_classes` (optional, one per row) colour rows by CSS class.
  void table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
             const std::vector<std::string>& row_classes = {});
  /// Writes `script` (gnuplot; it may refer to the files written with dataFile()) to plots/NAME.gp
  /// (NAME = `name`), runs gnuplot and embeds plots/NAME.png with `caption`.
  /// Returns false (and notes it in the report) when gnuplot failed.
  bool plot(const std::string& name, const std::string& script, const std::string& caption);
  /// Writes `content` to the data file `file` in plots/; returns its file name (relative to plots/).
  std::string dataFile(const std::string& file, const std::string& content);

  /// Plots embedded so far.
  std::size_t plotCount() const { return plots_; }
  /// The whole HTML document.
  std::string html() const;
  /// Writes the HTML atomically.
  void write(const std::string& path) const;

private:
  std::string title_, dir_, body_;
  std::size_t plots_ = 0;
};

/// HTML-escapes text.
std::string htmlEscape(const std::string& s);
/// Base64 of bytes.
std::string base64(const std::string& bytes);
/// Whether gnuplot runs here.
bool gnuplotAvailable();

/// The standard run plots: error over time, NIS with its band, top-view trajectories.
/// `prefix` names the files; returns the number of plots added.
int addRunPlots(HtmlReport& report, const RunSeries& series, const std::string& prefix, const std::string& title,
                double confidence);

}  // namespace viewline::tuning
