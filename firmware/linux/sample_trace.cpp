#include "sample_trace.h"

#include <cerrno>
#include <cstring>

#include "plinth/core/state.h"
#include "plinth/host/input_error.h"

namespace plinth::firmware {

namespace {
[[noreturn]] void fail(const std::string& path, const char* what) {
  throw host::InputError("--trace " + path + ": " + what + ": " + std::strerror(errno));
}
}  // namespace

SampleTrace::SampleTrace(const std::string& path, int axis_count, double t_origin)
    : path_(path), file_(std::fopen(path.c_str(), "w")), axis_count_(axis_count),
      t_origin_(t_origin) {
  if (!file_) fail(path, "cannot create it");
  std::fputs("# plinth-monitor --trace: one line per sample the estimators took\n"
             "# alarm, latched: 0 normal, 1 advisory, 2 warning, 3 alarm, 4 fault\n"
             "# phase: 0 full_contact, 1 sliding, 2 rocking, 3 slide_rocking, 4 overturned, "
             "5 fell; nan: not estimating\n"
             "# t_s\trisk\talarm\tlatched",
             file_.get());
  for (int axis = 0; axis < axis_count; ++axis) {
    const char name = axis == 0 ? 'x' : 'y';
    std::fprintf(file_.get(), "\tground_%c_m_s2\ttheta_%c_rad\tphase_%c", name, name, name);
  }
  std::fputc('\n', file_.get());
}

void SampleTrace::after_update(const MonitorUpdate& update, const Monitor& monitor) {
  const BoxStatus& s = *update.status;
  if (s.newest_sample_time_ns == last_sample_ns_) return;
  last_sample_ns_ = s.newest_sample_time_ns;
  std::FILE* f = file_.get();
  std::fprintf(f, "%.6f\t%.4f\t%d\t%d", static_cast<double>(s.time_ns) * 1e-9 - t_origin_, s.risk,
               static_cast<int>(s.alarm), static_cast<int>(s.latched));
  for (int axis = 0; axis < axis_count_; ++axis) {
    if (!s.estimating) {
      std::fputs("\tnan\tnan\tnan", f);
      continue;
    }
    const AxisStatus& a = s.axes[static_cast<std::size_t>(axis)];
    std::fprintf(f, "\t%.5f\t%.6f\t%d", monitor.ensemble(axis).nominal().ground().horizontal,
                 a.state[kTheta], static_cast<int>(a.mode.phase));
  }
  std::fputc('\n', f);
}

void SampleTrace::close() {
  if (!file_) return;
  std::FILE* f = file_.release();
  bool ok = std::fflush(f) == 0 && std::ferror(f) == 0;
  ok = std::fclose(f) == 0 && ok;
  if (!ok) fail(path_, "write failed");
}

}  // namespace plinth::firmware
