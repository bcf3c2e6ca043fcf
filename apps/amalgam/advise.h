#pragma once
/// \file `amalgam advise`'s measurement: every renderer rendered for the same time, repeatedly
/// and interleaved, its error against a converged full-detail estimate, error x time relative
/// to full detail with a 95 % interval over the repeats, set-up time and memory; the table and
/// the verdict (docs/cli.md, "advise"). advise_cmd.cpp runs it and draws the strip.

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "amalgam/load/load_scene.h"
#include "amalgam/render/render.h"
#include "common.h"

namespace amalgam::cli::advise {

/// One renderer advise compares.
struct Candidate {
  std::string name;  ///< as the table and the strip name it
  std::string key;   ///< as the JSON and --keep name it
  RenderOptions options;
  bool level_of_detail = false;  ///< amalgams or cells (else full detail)
};

/// The renderers compared: full detail, Embree where built, amalgams (stochastic at K = 1 and
/// 4, composite at K = 1) and, when the scene has meshes, the volumetric renderer.
std::vector<Candidate> candidates(const RenderOptions& base);

/// A ratio of error x time with its 95 % interval (Student's t over the repeats, on the log);
/// low == high == value with one repeat.
struct Ratio {
  double value = 1, low = 1, high = 1;
};

/// One render of a candidate.
struct Run {
  std::uint64_t seed = 0;
  double mse = 0, seconds = 0;
};

struct Measured {
  Candidate c;
  RenderOutput out;  ///< the first repeat's render (the strip's and --keep's image)
  std::vector<Run> runs;
  double setup_s = 0;      ///< what this renderer needs beyond reading the scene
  double setup_bytes = 0;  ///< memory its set-up added to the process (resident set)
  Ratio vs_full;           ///< full detail's MSE x time over this renderer's
  double rmse() const;     ///< over all repeats (root of the mean MSE)
  double seconds() const;  ///< mean render seconds
};

/// The scenes a measurement renders: the scene as loaded, and its objects as instances for the
/// volumetric renderer (null: the scene has no meshes, the volumetric renderer is not compared).
struct Scenes {
  const LoadedScene* scene = nullptr;
  std::shared_ptr<const LoadedScene> objects;
  double objects_bytes = 0;  ///< what loading `objects` added to the process
};

/// Renders every candidate `repeats` times for `budget` seconds each (rounds in candidate
/// order, repeat r with seed base.seed + r), against `ref`.
std::vector<Measured> measure(const Scenes& s, const RenderOptions& base, const RenderOutput& ref,
                              double budget, int repeats);

/// What the table says: the renderer with the best error per time, those tied with it within
/// the intervals, and the best level-of-detail renderer against the better full-detail one.
struct Verdict {
  std::size_t best = 0;           ///< index into the measured renderers
  std::vector<std::size_t> tied;  ///< others whose interval reaches the best's
  std::size_t best_lod = 0, best_full = 0;
  Ratio lod_vs_full;    ///< best_lod's error per time over best_full's
  std::string outcome;  ///< "pays off", "does not pay off" or "undecided"
};
Verdict judge(const std::vector<Measured>& ms);

/// Prints the table and the verdict.
void report(std::ostream& log, const std::vector<Measured>& ms, const Verdict& v, double budget,
            int repeats, const AdviseOptions& a);

/// The table as JSON (--json FILE or -).
void write_json(const AdviseOptions& a, const std::string& scene, double budget, int repeats,
                const RenderOutput& ref, const std::vector<Measured>& ms, const Verdict& v,
                double scene_bytes);

}  // namespace amalgam::cli::advise
