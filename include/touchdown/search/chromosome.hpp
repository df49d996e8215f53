#pragma once
/// \file
/// The violation search's chromosome (RLaGA paper, Fig. 3): a flat vector of
/// numbers, cut into nuclear genes (one scenario property each, 1–3 values)
/// that belong to composite genes (GeneGroup): the environment (the scene's
/// seed, then one nuclear gene per weather/light property of
/// scenario::property_bounds()), the marker (x, y), the dynamic objects (one
/// slot per possible object) and, beyond the source and switchable off, the
/// static objects and the distractor markers.
///
/// Every gene's range is its envelope row of the bounds table; a slot's kind
/// gene is 0 for "no object" and 1 + the kind's enumerator otherwise.
/// decode() applies the per-kind rows (a person's speed, a bird's altitude)
/// by clamping and repairs inconsistent slots by fixed rules
/// (docs/architecture.md, "The violation search" → "Chromosome and GA
/// operators"), so every chromosome of the right shape decodes to a valid
/// scenario. Fields that are not genes (map, time limit, the marker's
/// dictionary, id, size and yaw, the drone's start) come from the layout's
/// base scenario.
///
/// Thread-safety: a ChromosomeLayout is immutable after construction; its
/// const methods may run concurrently. Every method allocates its result.
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "touchdown/core/enum_names.hpp"
#include "touchdown/scenario/scenario.hpp"

namespace touchdown::search {

/// The composite genes of Fig. 3 (+ static objects and distractors).
enum class GeneGroup { Environment, Marker, DynamicObject, StaticObject, Distractor };

}  // namespace touchdown::search

template <>
struct touchdown::EnumNames<touchdown::search::GeneGroup> {
  static constexpr std::array<std::string_view, 5> names{"environment", "marker", "dynamic_object", "static_object",
                                                         "distractor"};
};

namespace touchdown::search {

inline std::string_view to_string(GeneGroup g) { return enum_name(g); }

/// One nuclear gene: a property of the scenario and where its values sit in
/// a chromosome.
struct NuclearGene {
  /// The scenario key it sets: "weather.fog", "marker.position", "seed",
  /// "dynamic_objects[2].speed", "dynamic_objects[2].kind".
  std::string name;
  GeneGroup group = GeneGroup::Environment;
  int slot = -1;            ///< object slot for the object groups, else -1
  int offset = 0;           ///< index of its first value in a chromosome
  int size = 1;             ///< number of values (2 for a position, 3 for a size)
  double min = 0, max = 0;  ///< range of every value (a kind/motion gene: its index range)
  bool integer = false;     ///< values are whole numbers
};

struct ChromosomeOptions {
  /// Dynamic-object slots, 0..6 (the bounds table's maximum; 0 = group off:
  /// decode keeps the base's objects). Slot genes: kind (0 absent, 1 person,
  /// 2 dog, 3 bird), position, heading_deg, speed, motion (0 still, 1 line,
  /// 2 circle, 3 wander), extent, size, altitude.
  int dynamic_slots = 6;
  /// Beyond the source: static-object slots, 0..12 (0 = group off: decode
  /// keeps the base's). Slot genes: kind (0 absent, 1 box, 2 chair, 3 pole,
  /// 4 tree), position, yaw_deg, size.
  int static_slots = 12;
  /// Beyond the source: distractor slots, 0..4 (0 = off: decode keeps the
  /// base's). Slot genes: kind (0 absent, 1 wrong_id, 2 lookalike, 3
  /// pattern), position, yaw_deg, size, id, flipped_bits.
  int distractor_slots = 4;
  /// rlaga: every decoded dynamic object gets motion External (the DQN
  /// drives it); its motion gene is kept but unused (encode writes 0).
  bool drive_objects = false;

  /// False (with "option: what") when a slot count is outside its range.
  [[nodiscard]] bool validate(std::string* why) const;
  /// The source's chromosome: static_slots = distractor_slots = 0.
  static ChromosomeOptions source();
};

/// A chromosome: the values of every nuclear gene, in genes() order.
using Chromosome = std::vector<double>;

class ChromosomeLayout {
 public:
  /// `base` gives every field that is not a gene (map, time limit, marker
  /// dictionary/id/size/yaw, drone start, gps error, and a switched-off
  /// group's objects). Throws InvalidArgument for invalid options or an
  /// invalid base.
  explicit ChromosomeLayout(scenario::Scenario base, const ChromosomeOptions& options = {});

  /// The nuclear genes in chromosome order: environment, marker, dynamic
  /// slots, static slots, distractor slots.
  [[nodiscard]] const std::vector<NuclearGene>& genes() const { return genes_; }
  /// Chromosome length (sum of the genes' sizes).
  [[nodiscard]] int values() const { return values_; }
  [[nodiscard]] const scenario::Scenario& base() const { return base_; }
  [[nodiscard]] const ChromosomeOptions& options() const { return options_; }

  /// The chromosome of `s`: object k in slot k, absent slots at their genes'
  /// minimums (kind 0). Throws InvalidArgument (naming the field) when s does
  /// not fit: an invalid scenario, more objects than slots, a non-gene field
  /// differing from the base, an External motion without drive_objects (or
  /// a scripted one with it).
  [[nodiscard]] Chromosome encode(const scenario::Scenario& s) const;
  /// Always returns a scenario that passes Scenario::validate(): per-kind
  /// bounds are applied by clamping, inconsistent slots (a distractor over
  /// the marker, a wrong_id equal to the marker id, a static object on the
  /// drone's start, ...) are repaired or dropped by a documented
  /// deterministic rule. Present slots become list elements in slot order.
  /// Throws InvalidArgument for a wrong length, NaN, a value outside its
  /// gene's range or a non-integer in an integer gene.
  [[nodiscard]] scenario::Scenario decode(std::span<const double> c) const;
  /// The seed pool's and the random method's draw: random_scenario(seed,
  /// base().map) projected onto the layout (non-gene fields from the base,
  /// objects beyond the slots dropped), repaired, encoded. Same seed, same
  /// chromosome.
  [[nodiscard]] Chromosome draw(std::uint64_t seed) const;
  /// The chromosome nearest `s`: its gene fields written with every value
  /// clamped into its gene's range (objects beyond the slots dropped), then
  /// repaired as decode() repairs; non-gene fields are the base's. For a
  /// scenario built by hand (the diversity option's covering pool). Throws
  /// InvalidArgument for NaN.
  [[nodiscard]] Chromosome fit(const scenario::Scenario& s) const;
  /// eq. 7's normalisation: each value mapped to [0, 1] by its gene's range
  /// (0 for a zero-width range); the values of an ABSENT object slot (kind
  /// 0) are 0 except the kind gene, so two scenarios without an object do
  /// not differ in its unused values. Same checks as decode().
  [[nodiscard]] std::vector<double> normalised(std::span<const double> c) const;
  /// The source's meta information of the dynamic-object gene: the number of
  /// present slots per kind (person, dog, bird). Same checks as decode().
  [[nodiscard]] std::array<int, 3> dynamic_counts(std::span<const double> c) const;

 private:
  void check(std::span<const double> c) const;
  // The genes of s written without the fit checks (values clamped into the
  // genes' ranges): encode() after its checks, draw() before the repair.
  [[nodiscard]] Chromosome write(const scenario::Scenario& s) const;
  void add_gene(std::string name, GeneGroup group, int slot, int size, double min, double max, bool integer);

  scenario::Scenario base_;
  ChromosomeOptions options_;
  std::vector<NuclearGene> genes_;
  int values_ = 0;
  int first_dynamic_ = 0;  // index in genes_ of dynamic slot 0's kind gene (a group's slots are contiguous)
};

}  // namespace touchdown::search
