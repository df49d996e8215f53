#pragma once
// ODE set-up and conversions shared by the twin's landings and the
// mission's drone (core's internal helpers: a module that includes it links
// touchdown_ode, src/CMakeLists.txt).
#include <ode/ode.h>

#include <Eigen/Core>
#include <cstdarg>
#include <mutex>

namespace touchdown::detail {

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

inline Eigen::Vector3d vec_of(const dReal* v) { return {v[0], v[1], v[2]}; }

// A body's rotation (ODE: 3x4 row-major).
inline Eigen::Matrix3d rotation_of(dBodyID b) {
  const dReal* r = dBodyGetRotation(b);
  Eigen::Matrix3d R;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) R(i, j) = r[i * 4 + j];
  return R;
}

// A rotation as ODE's 3x4 row-major matrix.
inline void to_ode(const Eigen::Matrix3d& M, dMatrix3 R) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) R[i * 4 + j] = M(i, j);
    R[i * 4 + 3] = 0;
  }
}

// A world for one airframe: its own single-threaded stepping (the
// library-wide default one is shared and must not step two worlds at once),
// gravity `g` [m/s²] down (−z), the contact settings of the twin, no
// auto-disable. Free with dWorldDestroy and
// dThreadingFreeImplementation(*threading).
inline dWorldID create_world(double g, dThreadingImplementationID* threading) {
  ensure_ode();
  dWorldID world = dWorldCreate();
  *threading = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(world, dThreadingImplementationGetFunctions(*threading), *threading);
  dWorldSetGravity(world, 0, 0, -g);
  dWorldSetContactSurfaceLayer(world, 0.0005);
  dWorldSetContactMaxCorrectingVel(world, 1.0);
  dWorldSetAutoDisableFlag(world, 0);
  return world;
}

// A rigid body of `mass` [kg] and inertia `I` about its centre of mass
// (an airframe's total_mass() and inertia_about_com()).
inline dBodyID create_rigid_body(dWorldID world, double mass, const Eigen::Matrix3d& I) {
  dBodyID body = dBodyCreate(world);
  dMass m;
  dMassSetParameters(&m, mass, 0, 0, 0, I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2));
  dBodySetMass(body, &m);
  return body;
}

}  // namespace touchdown::detail
