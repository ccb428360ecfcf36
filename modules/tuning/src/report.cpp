#include "viewline/tuning/report.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "viewline/core/error.h"
#include "viewline/core/statistics.h"
#include "viewline/io/files.h"

namespace viewline::tuning {

namespace fs = std::filesystem;

std::string htmlEscape(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string base64(const std::string& bytes) {
  static const char* tbl = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) | (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += tbl[(v >> 18) & 63];
    out += tbl[(v >> 12) & 63];
    out += tbl[(v >> 6) & 63];
    out += tbl[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += tbl[(v >> 18) & 63];
    out += tbl[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? tbl[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

bool gnuplotAvailable() { return std::system("gnuplot --version > /dev/null 2>&1") == 0; }

HtmlReport::HtmlReport(std::string title, std::string dir) : title_(std::move(title)), dir_(std::move(dir)) {
  fs::create_directories(fs::path(dir_) / "plots");
}

void HtmlReport::heading(const std::string& text, int level) {
  const std::string l = std::to_string(std::clamp(level, 1, 4));
  body_ += "<h" + l + ">" + htmlEscape(text) + "</h" + l + ">\n";
}

void HtmlReport::paragraph(const std::string& html) { body_ += "<p>" + html + "</p>\n"; }

void HtmlReport::preformatted(const std::string& text) { body_ += "<pre>" + htmlEscape(text) + "</pre>\n"; }

void HtmlReport::table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                       const std::vector<std::string>& row_classes) {
  body_ += "<table>\n<tr>";
  for (const auto& h : header) body_ += "<th>" + htmlEscape(h) + "</th>";
  body_ += "</tr>\n";
  for (std::size_t r = 0; r < rows.size(); ++r) {
    body_ += r < row_classes.size() && !row_classes[r].empty() ? "<tr class=\"" + row_classes[r] + "\">" : "<tr>";
    for (const auto& c : rows[r]) body_ += "<td>" + htmlEscape(c) + "</td>";
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

std::string HtmlReport::dataFile(const std::string& file, const std::string& content) {
  io::writeTextFileAtomic((fs::path(dir_) / "plots" / file).string(), content);  // errors name the file
  return file;
}

bool HtmlReport::plot(const std::string& name, const std::string& script, const std::string& caption) {
  const fs::path plots = fs::path(dir_) / "plots";
  const std::string png = name + ".png";
  std::ostringstream gp;
  gp << "# " << caption << "\n# re-plot: cd " << plots.string() << " && gnuplot " << name << ".gp\n"
     << "set terminal pngcairo size 960,480 font ',10' noenhanced\nset output '" << png << "'\nset grid\nset key outside right\n"
     << script << "\n";
  dataFile(name + ".gp", gp.str());
  fs::remove(plots / png);
  const std::string cmd = "cd '" + plots.string() + "' && gnuplot '" + name + ".gp' > '" + name + ".log' 2>&1";
  const int rc = std::system(cmd.c_str());
  std::ifstream in(plots / png, std::ios::binary);
  if (rc != 0 || !in) {
    body_ += "<p class=\"warn\">Plot '" + htmlEscape(name) + "' could not be rendered (gnuplot missing or failed; see plots/" +
             htmlEscape(name) + ".log). Data and script: plots/" + htmlEscape(name) + ".gp</p>\n";
    return false;
  }
  std::ostringstream bytes;
  bytes << in.rdbuf();
  body_ += "<figure><img alt=\"" + htmlEscape(name) + "\" src=\"data:image/png;base64," + base64(bytes.str()) +
           "\"/><figcaption>" + htmlEscape(caption) + "</figcaption></figure>\n";
  ++plots_;
  return true;
}

std::string HtmlReport::html() const {
  return "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + htmlEscape(title_) +
         "</title>\n<style>body{font-family:sans-serif;max-width:1100px;margin:auto;padding:1em}"
         "table{border-collapse:collapse;font-size:90%}td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}"
         "tr.best{background:#d8f5d0}tr.over{background:#fde2e2}tr.under{background:#e2ecfd}tr.incomplete{color:#999}"
         ".warn{color:#a00}pre{background:#f4f4f4;padding:.5em;overflow-x:auto}img{max-width:100%}"
         "figcaption{font-size:90%;color:#444}</style></head><body>\n<h1>" +
         htmlEscape(title_) + "</h1>\n" + body_ + "</body></html>\n";
}

void HtmlReport::write(const std::string& path) const { io::writeTextFileAtomic(path, html()); }

namespace {

std::string curvesData(const std::vector<Curve>& curves, std::size_t* blocks) {
  std::ostringstream os;
  os.precision(10);
  std::size_t b = 0;
  for (const Curve& c : curves) {
    if (c.x.empty()) continue;
    if (b) os << "\n\n";
    for (std::size_t i = 0; i < c.x.size() && i < c.y.size(); ++i) os << c.x[i] << ' ' << c.y[i] << '\n';
    ++b;
  }
  *blocks = b;
  return os.str();
}

std::string quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("''") : std::string(1, c);
  return o + "'";
}

}  // namespace

int addRunPlots(HtmlReport& report, const RunSeries& s, const std::string& prefix, const std::string& title,
                double confidence) {
  int added = 0;
  std::size_t nb = 0;
  const std::string err = curvesData(s.error, &nb);
  if (nb > 0) {
    report.dataFile(prefix + "_error.dat", err);
    std::ostringstream gp;
    gp << "set title " << quote(title + ": error over time") << "\nset xlabel " << quote(s.time_label)
       << "\nset ylabel " << quote(s.error_label) << "\nunset key\n"
       << "plot for [i=0:" << nb - 1 << "] '" << prefix << "_error.dat' index i using 1:2 with lines lw 1\n";
    added += report.plot(prefix + "_error", gp.str(), title + ": error over time (" + std::to_string(nb) + " curve(s))");
  }
  if (!s.nis.empty()) {
    const std::size_t w = std::min<std::size_t>(20, s.nis.size());
    std::ostringstream os;
    os.precision(10);
    double acc = 0.0;
    for (std::size_t i = 0; i < s.nis.size(); ++i) {
      acc += s.nis[i];
      if (i >= w) acc -= s.nis[i - w];
      const std::size_t n = std::min(i + 1, w);
      os << s.nis_t[i] << ' ' << s.nis[i] << ' ' << acc / static_cast<double>(n) << '\n';
    }
    report.dataFile(prefix + "_nis.dat", os.str());
    const core::Interval single = core::averagedChiSquareInterval(s.nis_dof, 1.0, confidence);
    const core::Interval moving = core::averagedChiSquareInterval(s.nis_dof, static_cast<double>(w), confidence);
    double sum = 0.0;
    for (double v : s.nis) sum += v;
    const double mean = sum / static_cast<double>(s.nis.size());
    const core::Interval all = core::averagedChiSquareInterval(s.nis_dof, static_cast<double>(s.nis.size()), confidence);
    std::ostringstream gp;
    gp.precision(6);
    gp << "set title " << quote(title + ": NIS (" + std::to_string(static_cast<int>(s.nis_dof)) + " dof)") << "\nset xlabel "
       << quote(s.nis_x_label) << "\nset ylabel 'NIS'\nset logscale y\n"
       << "set label 1 sprintf('mean %.3g, band of the mean [%.3g, %.3g]', " << mean << ", " << all.lo << ", " << all.hi
       << ") at graph 0.02, graph 0.95\n"
       << "plot '" << prefix << "_nis.dat' using 1:2 with points pt 7 ps 0.3 lc rgb '#9999cc' title 'NIS', "
       << "'' using 1:3 with lines lw 2 lc rgb '#0000aa' title 'moving mean (" << w << ")', "
       << moving.lo << " with lines dt 2 lw 2 lc rgb '#aa0000' title sprintf('%g %% band of a %d-sample mean', "
       << 100.0 * confidence << ", " << w << "), " << moving.hi << " with lines dt 2 lw 2 lc rgb '#aa0000' notitle, "
       << single.hi << " with lines dt 3 lc rgb '#666666' title 'single-sample upper bound', " << s.nis_dof
       << " with lines lc rgb '#00aa00' title 'dof (expected mean)'\n";
    added += report.plot(prefix + "_nis", gp.str(), title + ": NIS with its chi-square band");
  }
  std::size_t bt = 0, be = 0, bp = 0;
  const std::string tru = curvesData(s.truth, &bt), est = curvesData(s.estimate, &be), pre = curvesData(s.prediction, &bp);
  if (bt + be + bp > 0) {
    std::ostringstream gp;
    gp << "set title " << quote(title + ": trajectories (top view)") << "\nset xlabel " << quote(s.traj_x_label)
       << "\nset ylabel " << quote(s.traj_y_label) << "\nset size ratio -1\nplot ";
    std::string sep;
    auto add = [&](const std::string& file, const std::string& data, std::size_t n, const std::string& style,
                   const std::string& label) {
      if (n == 0) return;
      report.dataFile(file, data);
      gp << sep << "for [i=0:" << n - 1 << "] '" << file << "' index i using 1:2 " << style << " title (i==0 ? "
         << quote(label) << " : '')";
      sep = ", ";
    };
    add(prefix + "_truth.dat", tru, bt, "with lines lw 2 lc rgb 'black'", "truth");
    add(prefix + "_estimate.dat", est, be, "with linespoints pt 7 ps 0.4 lc rgb '#0060ff'", "estimate");
    add(prefix + "_prediction.dat", pre, bp, "with lines dt 2 lw 2 lc rgb '#e07000'", "prediction");
    gp << "\n";
    added += report.plot(prefix + "_trajectory", gp.str(), title + ": truth vs estimate vs prediction (top view)");
  }
  return added;
}

}  // namespace viewline::tuning
