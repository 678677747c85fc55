#include "native_log.h"

#include <glog/logging.h>

#include <atomic>
#include <deque>
#include <mutex>
#include <string>
#include <tuple>

namespace py = pybind11;

namespace boxplus::python {
namespace {

struct Record {
  int severity;
  std::string file;
  int line;
  std::string message;
};

// Enough for every message of a solve gone wrong many times over; past it the
// oldest are kept and the rest counted, so a flood cannot exhaust memory.
constexpr size_t kMaxQueued = 10000;

class QueueSink final : public google::LogSink {
 public:
  void send(google::LogSeverity severity, const char* /*full_filename*/, const char* base_filename,
            int line, const google::LogMessageTime& /*time*/, const char* message,
            size_t message_len) override {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (queue_.size() >= kMaxQueued) {
        ++dropped_;
        return;
      }
      queue_.push_back({static_cast<int>(severity), base_filename ? base_filename : "", line,
                        std::string(message, message_len)});
    }
    // At most one pending call at a time; it is cleared by Drain().
    if (!closed_.load() && !scheduled_.exchange(true)) {
      if (Py_AddPendingCall(&QueueSink::Deliver, nullptr) != 0) scheduled_ = false;
    }
  }

  std::deque<Record> Drain() {
    scheduled_ = false;
    std::lock_guard<std::mutex> lock(mutex_);
    std::deque<Record> out;
    out.swap(queue_);
    return out;
  }
  long long dropped() {
    std::lock_guard<std::mutex> lock(mutex_);
    return dropped_;
  }
  void Close() { closed_ = true; }

 private:
  // Runs in the main thread with the GIL held (a pending call): hands the
  // queue to boxplus.log.flush_native(). A failure there must not raise into
  // unrelated code, so it is printed and cleared.
  static int Deliver(void*) {
    PyObject* mod = PyImport_ImportModule("boxplus.log");
    PyObject* r = mod ? PyObject_CallMethod(mod, "flush_native", nullptr) : nullptr;
    if (!r) PyErr_WriteUnraisable(mod);
    Py_XDECREF(r);
    Py_XDECREF(mod);
    return 0;
  }

  std::mutex mutex_;
  std::deque<Record> queue_;
  long long dropped_ = 0;
  std::atomic<bool> scheduled_{false};
  std::atomic<bool> closed_{false};
};

// Never destroyed: glog may log from other threads until the process ends.
QueueSink* Sink() {
  static QueueSink* sink = new QueueSink;
  return sink;
}

}  // namespace

void RegisterNativeLog(py::module_& m) {
  if (!google::IsGoogleLoggingInitialized()) {
    // No log files (glog writes them to /tmp by default) and, below FATAL,
    // nothing on stderr: the sink below is the only destination.
    FLAGS_logtostderr = false;
    FLAGS_stderrthreshold = google::GLOG_FATAL;
    for (int s = google::GLOG_INFO; s < google::NUM_SEVERITIES; ++s) {
      google::SetLogDestination(s, "");
    }
    google::InitGoogleLogging("boxplus");
  }
  google::AddLogSink(Sink());
  // No pending calls once the interpreter is shutting down.
  py::module_::import("atexit").attr("register")(py::cpp_function([] { Sink()->Close(); }));

  m.def(
      "_native_log_drain",
      [] {
        py::list out;
        for (const Record& r : Sink()->Drain()) {
          // Messages may quote bytes of a file: undecodable ones are replaced.
          auto text = py::reinterpret_steal<py::object>(PyUnicode_DecodeUTF8(
              r.message.data(), static_cast<Py_ssize_t>(r.message.size()), "replace"));
          if (!text) throw py::error_already_set();
          out.append(py::make_tuple(r.severity, r.file, r.line, text));
        }
        return out;
      },
      "The queued glog messages of Ceres as (severity, file, line, message); "
      "severity 0 INFO, 1 WARNING, 2 ERROR, 3 FATAL. Used by boxplus.log.");
  m.def(
      "_native_log_emit",
      [](int severity, const std::string& message) {
        if (severity < google::GLOG_INFO || severity > google::GLOG_ERROR) {
          throw py::value_error("_native_log_emit: severity must be 0 (INFO), 1 or 2 (ERROR)");
        }
        py::gil_scoped_release release;  // as Ceres logs: from C++ without the GIL
        LOG_AT_LEVEL(severity) << message;
      },
      py::arg("severity"), py::arg("message"),
      "Logs one glog message from C++, as Ceres does (for the tests of the routing).");
  m.def(
      "_native_log_dropped", [] { return Sink()->dropped(); },
      "How many glog messages the full queue has dropped.");
}

}  // namespace boxplus::python
