#pragma once
/// \file The one walk loop every traversal of traverse.h runs: iterative, depth first, with an
/// explicit stack. What differs between hierarchies is the node source, a type given to the
/// loop (as bvh v2's traversal takes its inner and leaf functions):
/// - wide_walk.h, `ExplicitSource`: an explicit hierarchy's SoA child boxes and triangle packs;
/// - instanced_walk.h, `InstancedSource`: the two-level instanced hierarchy, which switches from
///   the top tree to an instance's mesh at an instance leaf;
/// - generic_walk.h, `GeneratorSource`: any hierarchy through `for_each_child` (the builtin
///   implicit scenes, whose children are computed on demand), in sorted or stored order.
///
/// A source supplies:
/// - `Item`: a stack entry, with at least `t` (where the ray enters it) and `level`;
/// - `Root`, `begin(s, root)` (the per-ray constants, kept as the loop's locals) and
///   `root_item(root, t)`;
/// - `node_id(s, ray_constants, it)`: the hierarchy's id of the node of `it`, asked for only
///   where the level-of-detail policy may render;
/// - `expand<kRays>(s, ray_constants, it, stack)`: a node the policy did not render: its
///   primitives tested, its hit children pushed; Next::kEnter with `it` the next node to enter;
/// - `kBoxKernel`: whether it tests boxes with the SIMD kernel (wide_kernels.h), whose loop is
///   compiled twice, for rays with and without zero direction components;
/// - optionally `box(it)`: the box of the node of `it`, kept from its test (default: the
///   hierarchy's `bounds`);
/// - optionally `pop(s, it, stack)`: the next item to enter (default: the nearest entry on the
///   stack not beyond the closest hit, `RayState::pop_nearer`).
/// The loop applies the ray state's rules (state.h): one reached node counted per node taken,
/// the policy's render-or-descend decision, the opacity model's effect of a rendered amalgam.

#include <cstddef>
#include <vector>

#include "amalgam/geometry/wide_kernels.h"
#include "amalgam/traverse/state.h"

namespace amalgam {
AMALGAM_ISA_BEGIN

/// What the walk does after a node: enter `it` (set by the source to the next node), pop the
/// stack, or stop (the ray is done: a shadow ray occluded). `done` is read only where it can
/// have changed (after a leaf or a rendered amalgam), not at every pop.
enum class Next { kEnter, kPop, kStop };

/// The walk's stack, its items `st[0, sp)`: the base and capacity are kept in this local view
/// (members of the walk would be reloaded after every store to the stack: a float store may
/// alias them); `store` owns the memory, kept across rays.
template <class Item>
struct WalkStack {
  explicit WalkStack(std::vector<Item>& s) : store(s), st(s.data()), cap(s.size()) {}
  /// Grows the stack to hold `need` items.
  [[gnu::always_inline]] void reserve(std::size_t need) { reserve_stack(store, st, cap, need); }

  std::vector<Item>& store;
  Item* st;
  std::size_t cap;
  std::size_t sp = 0;
};

template <class State, class Source>
class Walk {
 public:
  using Item = typename Source::Item;
  using Root = typename Source::Root;

  /// Traces `s.ray` from `root`, whose box the ray meets at `t_root`.
  void run(State& s, const Root& root, float t_root) {
    if (stack_.size() < 64) stack_.resize(64);
    if constexpr (Source::kBoxKernel) {
      // A ray with a zero direction component needs the box test's containment branch per
      // axis, and one with an infinite origin or inverse direction its NaN-skipping start;
      // all others (nearly every ray) run a loop without them.
      if (box_rays_simple(s.ray))
        loop<BoxRays::kNonZero>(s, root, t_root);
      else
        loop<BoxRays::kZeroAxes>(s, root, t_root);
    } else {
      loop<BoxRays::kZeroAxes>(s, root, t_root);
    }
  }

 private:
  template <BoxRays kRays>
  void loop(State& s, const Root& root, float t_root) {
    const auto rc = source_.begin(s, root);
    WalkStack<Item> st(stack_);
    Item it = Source::root_item(root, t_root);
    for (;;) {
      s.count_reached();
      const Next next =
          !s.render_if_policy([&] { return source_.node_id(s, rc, it); },
                              [&](NodeId id) { return box(s, it, id); }, it.level, it.t)
              ? source_.template expand<kRays>(s, rc, it, st)
          : s.done ? Next::kStop
                   : Next::kPop;
      if (next == Next::kEnter) continue;
      if (next == Next::kStop || !pop(s, it, st)) return;
    }
  }

  /// The box of node `id` (item `it`): kept by the source, or the hierarchy's.
  [[gnu::always_inline]] Bbox box(const State& s, const Item& it, NodeId id) const {
    if constexpr (requires { Source::box(it); })
      return Source::box(it);
    else
      return s.h.bounds(id);
  }

  [[gnu::always_inline]] bool pop(State& s, Item& it, WalkStack<Item>& st) {
    if constexpr (requires { source_.pop(s, it, st); })
      return source_.pop(s, it, st);
    else
      return s.pop_nearer(it, st.st, st.sp);
  }

  [[no_unique_address]] Source source_;
  std::vector<Item> stack_;
};

AMALGAM_ISA_END
}  // namespace amalgam
