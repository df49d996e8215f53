#pragma once
/// \file
/// The solids of the landing world, shared by the renderer and the
/// collision checker: the drone as its real shape (body box, arm capsules,
/// rotor disks, legs and feet of a twin::Airframe) and every scenario object
/// as a few boxes, cylinders, cones, spheres and capsules. Collisions are
/// computed with FCL (src/scenario/collision.cpp; FCL stays out of this
/// header).
///
/// Thread-safety: CollisionChecker is one per world (not shared).
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::twin {
struct Airframe;
}

namespace touchdown::scenario {

struct Solid {
  enum class Shape { Box, Cylinder, Cone, Sphere, Capsule };
  Shape shape = Shape::Box;
  /// Solid → parent frame. Cylinders, cones and capsules have their axis
  /// along local z and are centred on the origin (a cone's base at
  /// z = -height/2, its apex at +height/2).
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  /// box: full extents x, y, z; cylinder and cone: radius, radius, height;
  /// sphere: radius (x); capsule: radius (x), segment length (z).
  Eigen::Vector3d size{1, 1, 1};
  std::array<std::uint8_t, 3> bgr{128, 128, 128};  ///< base colour for the renderer
};

}  // namespace touchdown::scenario

template <>
struct touchdown::EnumNames<touchdown::scenario::Solid::Shape> {
  static constexpr std::array<std::string_view, 5> names{"box", "cylinder", "cone", "sphere", "capsule"};
};

namespace touchdown::scenario {

inline std::string_view to_string(Solid::Shape shape) { return enum_name(shape); }

/// The airframe's solids in its body frame (x forward, z up, origin at the
/// body centre): body box, arms, propeller disks (cylinders), legs and feet.
std::vector<Solid> drone_solids(const twin::Airframe& airframe);
/// A static object's solids in the world frame.
std::vector<Solid> object_solids(const StaticObject& object);
/// A moving object's solids in its own frame: origin on the ground (or at
/// the bird's centre) below its middle, x along its heading.
std::vector<Solid> object_solids(const DynamicObject& object);

/// Closest approach between the drone and one object.
struct Proximity {
  int object = -1;          ///< index given by add_object
  double distance = 0;      ///< ≥ 0 apart; < 0 penetration depth (negated)
  Eigen::Vector3d p_drone;  ///< closest (or contact) point on the drone, world frame
  Eigen::Vector3d p_object;
};

/// The drone against every object, with FCL (GJK/EPA on the real shapes).
class CollisionChecker {
 public:
  explicit CollisionChecker(const std::vector<Solid>& drone_in_body);
  ~CollisionChecker();
  CollisionChecker(CollisionChecker&&) noexcept;
  CollisionChecker& operator=(CollisionChecker&&) noexcept;

  /// Adds an object made of `solids` (in its own frame); returns its index.
  int add_object(const std::vector<Solid>& solids);
  [[nodiscard]] int object_count() const;

  /// True when the drone at T_world_body touches object `i` at
  /// T_world_object; fills *contact (distance < 0 or 0, points) when given.
  bool collide(int object, const Eigen::Isometry3d& T_world_body, const Eigen::Isometry3d& T_world_object,
               Proximity* contact = nullptr) const;
  /// Separation between the drone and object `i` (≥ 0; 0 when touching).
  Proximity distance(int object, const Eigen::Isometry3d& T_world_body, const Eigen::Isometry3d& T_world_object) const;
  /// The first object (in index order) the drone touches, or object = -1.
  /// Objects whose bounding spheres are apart are skipped without FCL.
  Proximity first_collision(const Eigen::Isometry3d& T_world_body,
                            const std::vector<Eigen::Isometry3d>& T_world_objects) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace touchdown::scenario
