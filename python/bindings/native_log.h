// Ceres' glog messages as Python logging records (logger "boxplus.ceres").
#pragma once

#include <pybind11/pybind11.h>

namespace boxplus::python {

// Initialises glog (unless the host process did) with no log files and
// nothing on stderr below FATAL, and routes its messages to Python: a glog
// sink queues each message and asks the interpreter, with Py_AddPendingCall,
// to hand the queue to boxplus.log once it runs Python code again. The sink
// may not take the GIL itself: glog holds its own mutex while calling sinks,
// and a thread holding the GIL could be waiting for that mutex.
// Binds _native_log_drain() (the queued messages as (severity, file, line,
// message) tuples) and _native_log_dropped() (how many a full queue dropped).
void RegisterNativeLog(pybind11::module_& m);

}  // namespace boxplus::python
