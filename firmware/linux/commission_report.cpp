#include "commission_report.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "commission_text.h"

namespace plinth::firmware {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

constexpr std::string_view kReportPrefix = "commission-";
constexpr std::string_view kReportSuffix = ".json";
// The picture's panels: the sensors a box file can hold (4 accelerometers and the statue's).
constexpr std::size_t kMaxPanels = 5;

double rounded(double value, double step) { return std::round(value / step) * step; }

Json window_json(const Window& w) {
  if (!w.found()) return nullptr;
  return Json{{"t0", rounded(w.t0, 1e-3)},
              {"t1", rounded(w.t1, 1e-3)},
              {"from", window_source_name(w.source)}};
}

// Whether every check of a step passed (its checks are named after it).
bool step_passed(const CommissionResult& result, const Step& step) {
  return std::none_of(result.checks.begin(), result.checks.end(), [&](const CheckResult& c) {
    return !c.passed && c.check.rfind(step.name, 0) == 0;
  });
}

// Plain characters only: the title reaches gnuplot as a string literal.
std::string plain(const std::string& text) {
  std::string out;
  for (const char c : text) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      std::string_view(" .,:;_+-()[]/=").find(c) != std::string_view::npos;
    out.push_back(keep ? c : '_');
  }
  return out.substr(0, 160);
}

void write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out.flush()) throw std::runtime_error("cannot write " + path.string());
}

// gnuplot's script: numbers, the program's labels and the plain title only.
std::string picture_script(const CommissionResult& result, std::size_t panels,
                           const std::string& title, double t_end) {
  std::ostringstream gp;
  gp << "set terminal pngcairo size 1100," << 120 + 260 * panels
     << " font \"DejaVu Sans,10\" noenhanced\n"
     << "set output \"commission.png\"\nset datafile separator \"\\t\"\n"
     << "set multiplot layout " << panels << ",1 title \"" << plain(title) << "\" font \",12\"\n"
     << "set lmargin at screen 0.08\nset rmargin at screen 0.97\n"
     << "set xrange [0:" << t_end << "]\nset grid xtics ytics lc rgb \"#dddddd\"\n"
     << "set key top left opaque box lc rgb \"#bbbbbb\"\n"
     << "set ylabel \"side raised (deg, from the first rest)\"\n";
  for (std::size_t p = 0; p < panels; ++p) {
    const SensorTrace& trace = result.traces[p];
    gp << "unset object\nunset label\nset title \"" << plain(trace.label) << "\"\n";
    gp << (p + 1 == panels ? "set xlabel \"time in the session (s)\"\nset format x \"%g\"\n"
                           : "unset xlabel\nset format x \"\"\n");
    int object = 1;
    for (const StepWindows& w : result.windows) {
      // The rests and this sensor's own steps.
      if (!w.hold.found() || (w.step.sensor >= 0 && w.step.sensor != trace.sensor)) continue;
      const bool passed = step_passed(result, w.step);
      gp << "set object " << object << " rect from " << w.hold.t0 << ", graph 0 to " << w.hold.t1
         << ", graph 1 fc rgb \"" << (passed ? "#c8ecc8" : "#f4c0c0")
         << "\" fs solid 0.6 noborder behind\n";
      gp << "set label " << object << " \"" << w.step.name << "\" at "
         << 0.5 * (w.hold.t0 + w.hold.t1) << ", graph 0.06 center font \",8\"\n";
      ++object;
    }
    const std::string data = format_text("sensor-%zu.tsv", p);
    gp << "plot \"" << data << "\" using 1:2 with lines lw 2 lc rgb \"#1f77b4\" title "
       << "\"+x side (accelerometer)\", \"" << data << "\" using 1:3 with lines lw 2 "
       << "lc rgb \"#ff7f0e\" title \"+y side (accelerometer)\"";
    if (trace.statue && !trace.gyro_t.empty()) {
      const std::string gyro = format_text("gyro-%zu.tsv", p);
      gp << ", \"" << gyro << "\" using 1:2 with lines dt 2 lw 2 lc rgb \"#08306b\" title "
         << "\"+x side (gyroscope)\", \"" << gyro << "\" using 1:3 with lines dt 2 lw 2 "
         << "lc rgb \"#a63603\" title \"+y side (gyroscope)\"";
    }
    gp << "\n";
  }
  gp << "unset multiplot\n";
  return gp.str();
}

std::string series(const std::vector<double>& t, const std::vector<double>& a,
                   const std::vector<double>& b) {
  std::string out;
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (std::isnan(t[k])) {
      out += "\n";  // a break between raises
      continue;
    }
    out += format_text("%.4f\t%.5f\t%.5f\n", t[k], a[k], b[k]);
  }
  return out;
}

}  // namespace

std::string report_json(const CommissionResult& result, const ReportContext& c) {
  Json report;
  report["type"] = "commissioning";
  report["format"] = 1;
  report["result"] = result.passed ? "pass" : "fail";
  report["time"] = c.time_utc;
  report["version"] = c.version;
  report["box_file"] = c.box_file;
  report["box_file_sha256"] = c.box_file_sha256;
  report["mounting_sha256"] = c.mounting_sha256;
  Json source;
  if (!c.interface_name.empty()) source["interface"] = c.interface_name;
  if (!c.log_path.empty()) {
    source["log"] = c.log_path;
    source["log_sha256"] = c.log_sha256;
  }
  report["source"] = source;
  report["record"] = c.record_name.empty() ? Json(nullptr) : Json(c.record_name);
  report["picture"] = c.picture_name.empty() ? Json(nullptr) : Json(c.picture_name);
  if (!c.picture_note.empty()) report["picture_note"] = c.picture_note;
  const CommissioningSettings& s = c.settings;
  report["settings"] = Json{{"sample_rate_hz", c.sample_rate_hz},
                            {"axes", c.axis_count},
                            {"wedge_deg", s.wedge_deg},
                            {"wedge_tolerance_deg", s.wedge_tolerance_deg},
                            {"heading_tolerance_deg", s.heading_tolerance_deg},
                            {"gravity_tolerance", s.gravity_tolerance},
                            {"level_tolerance_deg", s.level_tolerance_deg},
                            {"statue_min_tilt_deg", s.statue_min_tilt_deg},
                            {"gyro_tolerance", s.gyro_tolerance},
                            {"seat_tolerance_deg", s.seat_tolerance_deg}};
  Json failures = Json::array();
  for (const std::string& f : result.failures()) failures.push_back(f);
  report["failures"] = failures;
  Json notes = Json::array();
  for (const std::string& n : result.notes) notes.push_back(n);
  report["notes"] = notes;
  Json steps = Json::array();
  for (const StepWindows& w : result.windows) {
    Json step{{"step", w.step.name}, {"window", window_json(w.hold)}};
    if (w.step.kind == StepKind::kStatueRaise) {
      step["before"] = window_json(w.before);
      step["after"] = window_json(w.after);
    }
    step["passed"] = step_passed(result, w.step);
    steps.push_back(step);
  }
  report["steps"] = steps;
  Json checks = Json::array();
  for (const CheckResult& check : result.checks) {
    checks.push_back(Json{{"subject", check.subject},
                          {"check", check.check},
                          {"result", check.passed ? "pass" : "fail"},
                          {"measured", check.measured},
                          {"expected", check.expected},
                          {"message", check.message}});
  }
  report["checks"] = checks;
  return report.dump(2) + "\n";
}

std::string summary_text(const CommissionResult& result) {
  std::string out;
  const std::vector<std::string> failures = result.failures();
  std::size_t passed = 0;
  for (const CheckResult& c : result.checks) passed += c.passed ? 1 : 0;
  out += format_text("commissioning %s: %zu of %zu checks passed\n",
                     result.passed ? "PASSED" : "FAILED", passed, result.checks.size());
  for (const std::string& f : failures) out += "  FAIL " + f + "\n";
  for (const std::string& n : result.notes) out += "  note: " + n + "\n";
  return out;
}

std::string draw_picture(const CommissionResult& result, const std::string& title,
                         std::string& error) {
  const std::size_t panels = std::min(result.traces.size(), kMaxPanels);
  if (panels == 0) {
    error = "no sensor was heard: nothing to draw";
    return "";
  }
  std::string pattern = (fs::temp_directory_path() / "plinth-commission.XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) {
    error = "cannot make a private folder for gnuplot in " + fs::temp_directory_path().string();
    return "";
  }
  const fs::path folder(pattern);
  std::string png;
  try {
    double t_end = 1.0;
    for (std::size_t p = 0; p < panels; ++p) {
      const SensorTrace& trace = result.traces[p];
      if (!trace.t.empty()) t_end = std::max(t_end, trace.t.back());
      write_text(folder / format_text("sensor-%zu.tsv", p),
                 series(trace.t, trace.raise_x_deg, trace.raise_y_deg));
      if (trace.statue) {
        write_text(folder / format_text("gyro-%zu.tsv", p),
                   series(trace.gyro_t, trace.gyro_raise_x_deg, trace.gyro_raise_y_deg));
      }
    }
    write_text(folder / "commission.gp", picture_script(result, panels, title, t_end));
    const pid_t child = ::fork();
    if (child == 0) {
      if (::chdir(folder.c_str()) != 0) ::_exit(126);
      std::FILE* log = std::freopen("gnuplot.err", "w", stderr);
      std::FILE* in = std::freopen("/dev/null", "r", stdin);
      if (log == nullptr || in == nullptr) ::_exit(126);
      ::execlp("gnuplot", "gnuplot", "commission.gp", static_cast<char*>(nullptr));
      ::_exit(127);
    }
    int status = 0;
    if (child < 0 || ::waitpid(child, &status, 0) != child) {
      error = "cannot run gnuplot";
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == 127) {
      error = "gnuplot is not installed (apt install gnuplot-nox): no picture";
    } else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::ifstream err(folder / "gnuplot.err");
      std::string line;
      std::getline(err, line);
      error = "gnuplot failed: " + line;
    } else {
      std::ifstream in(folder / "commission.png", std::ios::binary);
      png.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
      if (png.empty()) error = "gnuplot drew nothing";
    }
  } catch (const std::exception& e) {
    error = e.what();
    png.clear();
  }
  std::error_code ignored;
  fs::remove_all(folder, ignored);
  return png;
}

std::string report_stem(int index) { return format_text("commission-%03d", index); }

int newest_report_index(const std::string& directory) {
  int newest = 0;
  std::error_code e;
  for (fs::directory_iterator it(directory, e), end; !e && it != end; it.increment(e)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= kReportPrefix.size() + kReportSuffix.size() ||
        name.compare(0, kReportPrefix.size(), kReportPrefix) != 0 ||
        name.compare(name.size() - kReportSuffix.size(), kReportSuffix.size(), kReportSuffix) !=
            0) {
      continue;
    }
    const std::string digits = name.substr(
        kReportPrefix.size(), name.size() - kReportPrefix.size() - kReportSuffix.size());
    if (digits.empty() || digits.size() > 6 ||
        !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      continue;
    }
    newest = std::max(newest, std::stoi(digits));
  }
  return newest;
}

bool write_report_file(const std::string& directory, const std::string& name,
                       const std::string& text, std::string& error) {
  const fs::path final_path = fs::path(directory) / name;
  const fs::path partial = fs::path(directory) / ("." + name + ".partial");
  const auto failed = [&](const char* what, const fs::path& path) {
    error = std::string("cannot ") + what + " " + path.string() + ": " + std::strerror(errno);
    ::unlink(partial.c_str());
    return false;
  };
  std::error_code exists_error;
  if (fs::exists(fs::symlink_status(final_path, exists_error))) {
    error = final_path.string() + " exists already: a report is never written over";
    return false;
  }
  ::unlink(partial.c_str());  // a partial file left by a killed run, or a symlink: never opened
  const int fd =
      ::open(partial.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) return failed("create", partial);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(fd);
      return failed("write", partial);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    ::close(fd);
    return failed("flush", partial);
  }
  if (::close(fd) != 0) return failed("close", partial);
  if (::rename(partial.c_str(), final_path.c_str()) != 0) return failed("rename", partial);
  const int dir = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  const bool synced = dir >= 0 && ::fsync(dir) == 0;
  if (dir >= 0) ::close(dir);
  if (!synced) {
    error = "cannot flush the folder " + directory + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return text;
}

}  // namespace plinth::firmware
