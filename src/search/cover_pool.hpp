#pragma once
// The diversity option's covering seed pools (SearchOptions::diversity_pool =
// Cover, CoverDrawn or CoverMixed; docs/architecture.md, "The violation search" → "Distinct
// defects"); private to the search module.
#include <cstdint>
#include <string>
#include <vector>

#include "touchdown/search/chromosome.hpp"

namespace touchdown::search::detail {

/// One member of the covering design: a scene with one condition at the
/// severe end of its range, on a benign or a drawn background.
struct CoverMember {
  std::string condition;  ///< "fog", "low light", "lookalike near the marker", ...
  scenario::Scenario scenario;
};

/// The conditions the layout can express, in pool order: the environment's
/// and the object kinds' alternately (so a pool smaller than the list still
/// covers both), environment first. A group switched off in the layout
/// (0 slots) contributes none.
std::vector<std::string> cover_conditions(const ChromosomeOptions& options);

/// What a member's other factors are.
enum class Background {
  Benign,  ///< no other weather, no other object (SeedPool::Cover)
  Drawn,   ///< as random sampling draws them (SeedPool::CoverDrawn)
  /// Benign for a moving object's condition (person, dog, bird), Drawn for
  /// every other (SeedPool::CoverMixed): member k is then exactly the
  /// Benign or the Drawn pool's member k.
  Mixed,
};

/// Members first .. first + n − 1 of the covering pool (member k covers
/// condition k mod the list's size). Member k starts from
/// layout.draw(seed of its own stream k): its scene seed and marker position
/// (and the base's non-gene fields). On a benign background the weather is
/// made benign (no fog, precipitation, dust, ground cover or wet ground; the
/// sun 45–90° high; ambient 0.85–1) and every object removed; on a drawn one
/// the draw is kept. Then its condition is set (an object goes first in its
/// kind's list, so the chromosome's slots keep it):
/// a weather property in the severe tenth of its range (the top tenth of an
/// intensity, the bottom tenth of ambient or sun elevation: boundary-value
/// testing, jittered so that seeds differ), or one object of the kind
/// placed by the marker: a distractor in the top tenth of its size range,
/// 0–1 m beyond touching the marker's square (white margins included); a person, dog or bird starting within
/// 3 m of it, wandering (or driven, rlaga) in the landing column, a bird
/// 3–8 m above the ground; a box, chair, pole or tree 1.5–3.5 m from it
/// in the top tenth of its kind's sizes. Deterministic in (seed, k).
std::vector<CoverMember> cover_pool(const ChromosomeLayout& layout, std::uint64_t seed, int first, int n,
                                    Background background = Background::Benign);

}  // namespace touchdown::search::detail
