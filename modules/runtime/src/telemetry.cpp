#include "viewline/runtime/telemetry.h"

#include <limits>
#include <sstream>

#include "viewline/io/log.h"

namespace viewline::runtime {

std::vector<InnovationRecord> MemorySink::innovationsOf(const std::string& channel) const {
  std::vector<InnovationRecord> out;
  for (const auto& r : innovations)
    if (channel.empty() || r.channel == channel) out.push_back(r);
  return out;
}

std::size_t MemorySink::count(tracking::GateDecision d, const std::string& channel) const {
  std::size_t n = 0;
  for (const auto& r : innovations)
    if (r.decision == d && (channel.empty() || r.channel == channel)) ++n;
  return n;
}

void MemorySink::clear() {
  measurements.clear();
  innovations.clear();
  estimates.clear();
  commands.clear();
  scalars.clear();
}

namespace {
std::vector<std::string> indexed(const std::string& prefix, Eigen::Index n) {
  std::vector<std::string> h;
  for (Eigen::Index i = 0; i < n; ++i) h.push_back(prefix + std::to_string(i));
  return h;
}
void append(std::vector<std::string>& a, const std::vector<std::string>& b) { a.insert(a.end(), b.begin(), b.end()); }
void append(std::vector<double>& a, const Eigen::MatrixXd& m) {
  for (Eigen::Index i = 0; i < m.size(); ++i) a.push_back(m.data()[i]);
}
}  // namespace

CsvSink::CsvSink(io::LogDirectory& log) : log_(log) {}

void CsvSink::measurement(const MeasurementRecord& r) {
  if (!log_.enabled()) return;
  std::vector<std::string> h{"t", "id"};
  append(h, indexed("z", r.z.size()));
  append(h, indexed("sigma", r.sigma.size()));
  std::vector<double> row{r.t, static_cast<double>(r.id)};
  append(row, r.z);
  append(row, r.sigma);
  log_.stream("measurements_" + r.channel, h, 17).row(row);
}

void CsvSink::innovation(const InnovationRecord& r) {
  if (!log_.enabled()) return;
  // Start decisions have no innovation: their columns are NaN ("missing").
  const Eigen::Index m = r.rows;
  std::vector<std::string> h{"t", "id", "source", "decision", "nis"};
  std::vector<double> row{r.t, static_cast<double>(r.id), static_cast<double>(r.source),
                          static_cast<double>(static_cast<int>(r.decision)), r.nis};
  append(h, indexed("d", m));
  append(h, indexed("S", m * m));  // column-major
  auto& w = log_.stream("innovations_" + r.channel, h, 17);
  if (r.innovation.size() == m && r.S.rows() == m && r.S.cols() == m) {
    append(row, r.innovation);
    append(row, r.S);
  }
  row.resize(w.header().size(), std::numeric_limits<double>::quiet_NaN());
  w.row(row);
}

void CsvSink::estimate(const EstimateRecord& r) {
  if (!log_.enabled()) return;
  std::vector<std::string> h{"t"};
  append(h, indexed("x", r.x.size()));
  append(h, indexed("P", r.P.size()));
  std::vector<double> row{r.t};
  append(row, r.x);
  append(row, r.P);
  log_.stream("estimates_" + r.channel, h, 17).row(row);
}

void CsvSink::command(const CommandRecord& r) {
  if (!log_.enabled()) return;
  std::vector<std::string> h{"t"};
  append(h, indexed("u", r.u.size()));
  std::vector<double> row{r.t};
  append(row, r.u);
  log_.stream("commands_" + r.channel, h, 17).row(row);
}

void CsvSink::scalar(const ScalarRecord& r) {
  if (!log_.enabled()) return;
  std::ostringstream t, v;
  t.precision(17);
  v.precision(17);
  t << r.t;
  v << r.value;
  log_.stream("scalars", {"t", "channel", "value"}, 17).rowText({t.str(), r.channel, v.str()});
}

void CsvSink::flush() { log_.flush(); }

void FanoutSink::add(TelemetrySink* sink) {
  if (sink) sinks_.push_back(sink);
}
void FanoutSink::measurement(const MeasurementRecord& r) {
  for (auto* s : sinks_) s->measurement(r);
}
void FanoutSink::innovation(const InnovationRecord& r) {
  for (auto* s : sinks_) s->innovation(r);
}
void FanoutSink::estimate(const EstimateRecord& r) {
  for (auto* s : sinks_) s->estimate(r);
}
void FanoutSink::command(const CommandRecord& r) {
  for (auto* s : sinks_) s->command(r);
}
void FanoutSink::scalar(const ScalarRecord& r) {
  for (auto* s : sinks_) s->scalar(r);
}
void FanoutSink::flush() {
  for (auto* s : sinks_) s->flush();
}

}  // namespace viewline::runtime
