#include "commission_gate.h"

#include <sys/stat.h>
#include <syslog.h>
// No CODE_FILE/CODE_LINE in the entries (as supervisor.cpp).
#define SD_JOURNAL_SUPPRESS_LOCATION
#include <systemd/sd-journal.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <utility>

#include "commission_report.h"
#include "plinth/host/text_file.h"
#include "status_json.h"

namespace plinth::firmware {

namespace {

namespace fs = std::filesystem;
constexpr std::size_t kMaxReportBytes = std::size_t{16} << 20;  // a report is tens of kB

std::int64_t mtime_ns(const std::string& path) {
  struct stat st {};
  if (path.empty() || ::stat(path.c_str(), &st) != 0) return -1;
  return static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec;
}

}  // namespace

const char* gate_state_name(GateState state) {
  switch (state) {
    case GateState::kPassed:
      return "passed";
    case GateState::kRefused:
      return "refused";
    case GateState::kOverridden:
      return "overridden";
    case GateState::kNone:
      break;
  }
  return "none";
}

CommissioningGate::CommissioningGate(const CommissioningSettings& settings, std::string record_dir,
                                     std::string mounting_sha256, std::string override_option)
    : settings_(settings),
      record_dir_(std::move(record_dir)),
      mounting_sha256_(std::move(mounting_sha256)) {
  if (!override_option.empty()) {
    override_reason_ = std::move(override_option);
    override_source_ = "--commissioning-override";
  } else if (!settings.override_reason.empty()) {
    override_reason_ = settings.override_reason;
    override_source_ = "commissioning.override";
  }
}

GateVerdict CommissioningGate::evaluate() const {
  GateVerdict v;
  if (!settings_.report.empty()) {
    v.report = settings_.report;
  } else if (!record_dir_.empty()) {
    const int newest = newest_report_index(record_dir_);
    if (newest > 0) v.report = (fs::path(record_dir_) / (report_stem(newest) + ".json")).string();
  }
  const auto refuse = [&](std::string why) {
    v.state = GateState::kRefused;
    v.why = std::move(why);
  };
  if (v.report.empty()) {
    const std::string where = record_dir_.empty()
                                  ? std::string("no --record-dir, no commissioning.report")
                                  : "none in " + record_dir_;
    if (settings_.required) {
      refuse("commissioning.required, and no report (" + where + ")");
    } else {
      v.why = where;
    }
  } else {
    try {
      const nlohmann::json r = nlohmann::json::parse(
          host::read_text_file(v.report, kMaxReportBytes, "commissioning report"));
      if (!r.is_object() || r.value("type", "") != "commissioning") {
        refuse(v.report + ": not a commissioning report");
      } else {
        v.report_time = r.value("time", "");
        const std::string result = r.value("result", "");
        const std::string mounting = r.value("mounting_sha256", "");
        if (result != "pass") {
          const nlohmann::json& failures = r.value("failures", nlohmann::json::array());
          std::string first = failures.is_array() && !failures.empty() && failures[0].is_string()
                                  ? failures[0].get<std::string>()
                                  : std::string("no failure named");
          refuse(v.report + " failed (" +
                 std::to_string(failures.is_array() ? failures.size() : 0U) +
                 " checks; the first: " + first + ")");
        } else if (mounting != mounting_sha256_) {
          refuse(v.report + " passed for another mounting (its mounting_sha256 " +
                 mounting.substr(0, 12) + "..., this box file's " + mounting_sha256_.substr(0, 12) +
                 "...): the box file's sensors changed since; commission again");
        } else {
          v.state = GateState::kPassed;
        }
      }
    } catch (const std::exception& e) {
      refuse("cannot read the commissioning report: " + std::string(e.what()));
    }
  }
  if (v.state == GateState::kRefused && !override_reason_.empty()) {
    v.state = GateState::kOverridden;
  }
  return v;
}

std::int64_t CommissioningGate::watched_stamp() const {
  const std::int64_t folder = record_dir_.empty() ? -1 : mtime_ns(record_dir_);
  const std::int64_t report =
      mtime_ns(settings_.report.empty() ? verdict_.report : settings_.report);
  // Compared for equality only: mixed in unsigned arithmetic (wraps, never overflows).
  return static_cast<std::int64_t>(static_cast<std::uint64_t>(folder) * 31U +
                                   static_cast<std::uint64_t>(report));
}

const GateVerdict& CommissioningGate::check() {
  verdict_ = evaluate();
  stamp_ = watched_stamp();
  return verdict_;
}

bool CommissioningGate::poll(std::int64_t now_ns) {
  if (now_ns < next_look_ns_) return false;
  next_look_ns_ = now_ns + std::llround(kGateRescanS * 1e9);
  const std::int64_t stamp = watched_stamp();
  if (stamp == stamp_) return false;
  const GateVerdict before = verdict_;
  check();
  return verdict_.state != before.state || verdict_.report != before.report;
}

std::string CommissioningGate::message() const {
  const GateVerdict& v = verdict_;
  switch (v.state) {
    case GateState::kRefused:
      return "fault: commissioning: " + v.why +
             "; the box does not vouch for the statue: it shows fault (cause "
             "commissioning_failed) until a passing report (plinth-commission) or an override "
             "(commissioning.override, or --commissioning-override REASON)";
    case GateState::kOverridden:
      return "warning: commissioning overridden by " + override_source_ + " (\"" +
             override_reason_ + "\"): " + v.why + "; monitoring as if it had passed";
    case GateState::kPassed:
      return "commissioning: " + v.report + " passed (" + v.report_time + ")";
    case GateState::kNone:
      break;
  }
  return "warning: no commissioning report (" + v.why +
         "): run plinth-commission (docs/commissioning.md); monitoring without one";
}

void CommissioningGate::announce() const {
  const std::string text = message();
  const char* invocation = std::getenv("INVOCATION_ID");  // under systemd (supervisor.h)
  if (invocation == nullptr || invocation[0] == '\0') {
    std::fprintf(stderr, "plinth-monitor: %s\n", text.c_str());
    return;
  }
  const int priority = verdict_.state == GateState::kRefused  ? LOG_CRIT
                       : verdict_.state == GateState::kPassed ? LOG_NOTICE
                                                              : LOG_WARNING;
  if (sd_journal_send("MESSAGE=%s", text.c_str(), "PRIORITY=%d", priority,
                      "SYSLOG_IDENTIFIER=plinth-monitor", "PLINTH_COMMISSIONING=%s",
                      gate_state_name(verdict_.state), "PLINTH_COMMISSIONING_REPORT=%s",
                      verdict_.report.c_str(), nullptr) < 0) {
    std::fprintf(stderr, "plinth-monitor: %s\n", text.c_str());
  }
}

std::string CommissioningGate::json() const {
  JsonObject o;
  o.text("state", gate_state_name(verdict_.state));
  if (verdict_.state == GateState::kRefused) o.text("cause", "commissioning_failed");
  o.text("report", verdict_.report);
  if (!verdict_.report_time.empty()) o.text("report_time", verdict_.report_time);
  if (!verdict_.why.empty()) o.text("why", verdict_.why);
  if (verdict_.state == GateState::kOverridden) {
    o.text("override", override_reason_).text("override_by", override_source_);
  }
  return o.close();
}

std::string CommissioningGate::status_member() const { return "\"commissioning\": " + json(); }

}  // namespace plinth::firmware
