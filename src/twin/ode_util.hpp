#pragma once
// ODE set-up shared by the twin's landings and the mission's drone
// (internal; include only from sources that link ODE).
#include <ode/ode.h>

#include <cstdarg>
#include <mutex>

namespace touchdown::twin::detail {

// ODE's global initialisation (once per process) and this thread's data
// (every thread that steps a world).
inline void ensure_ode() {
  static std::once_flag once;
  std::call_once(once, [] {
    dInitODE2(0);
    // ODE prints solver notes (e.g. "LCP internal error, s <= 0" when a
    // pivot degenerates; the step still completes) to stderr, which would
    // corrupt the apps' output. Instability is detected from the state instead.
    dSetMessageHandler([](int, const char*, va_list) {});
  });
  dAllocateODEDataForThread(dAllocateMaskAll);
}

// ODE's ERP/CFM for a spring-damper contact (ODE manual, "Joint error and
// the error reduction parameter", "Soft constraint and constraint force mixing").
inline void soft_params(double h, double kp, double kd, double& erp, double& cfm) {
  erp = h * kp / (h * kp + kd);
  cfm = 1.0 / (h * kp + kd);
}

}  // namespace touchdown::twin::detail
