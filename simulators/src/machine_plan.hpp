#pragma once
// Planning one parsed block against the modal state: absolute target, duration (the time
// model) and geometry. Pure functions, used by Machine at submit time.
#include "machine.hpp"

namespace lamina::sim::detail {

// Check `block` against `modal` and plan it from `from`. On success `modal` takes the block's
// modal changes and `out` holds the plan (seq, submit time and source are the caller's); on
// an error neither changes.
GrblStatus plan_block(const Block& block, ModalState& modal, const AxisValues& from,
                      const MachineConfig& config, PlannedBlock& out);

// Position at path fraction s ∈ [0, 1] of a planned block.
AxisValues interpolate(const PlannedBlock& block, double s);

// True when the block stays inside the soft limits (target; arcs also along the way).
bool within_soft_limits(const PlannedBlock& block, const MachineConfig& config);

}  // namespace lamina::sim::detail
