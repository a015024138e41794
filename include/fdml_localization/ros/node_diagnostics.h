/**
 * @file node_diagnostics.h
 * @brief The localizer node's diagnostics: a summary of its state (map, last solve, ambiguity)
 *        and every counter (readings received and dropped by reason, batches, maps).
 */
#pragma once

#include "fdml_localization/ros/node_state.h"
#include "fdml_localization/ros/params.h"

#include <diagnostic_updater/diagnostic_updater.h>

namespace fdml_localization
{
/// Fills @p status from @p state (the caller holds state.mutex).
void diagnoseLocked(const NodeState& state, const Params& params, diagnostic_updater::DiagnosticStatusWrapper& status);

}  // namespace fdml_localization
