#pragma once
// Windows of consecutive rounds of a functional stepping (every busy context or group takes one
// step per round): the run's phases as the analytic level prices them (fill, steady state,
// drain; sim/analytic/estimate.cpp). At most `max_windows` are kept: when they are full,
// neighbours merge and the windows double in length, so a run of any length ends with between
// max_windows / 2 and max_windows windows of equal length (the last one partial).
#include <cstddef>
#include <utility>
#include <vector>

namespace rtsim {

/// Ends a round in the last of `windows` (its counts added by the caller; Window has `rounds`):
/// when the last holds `*window_rounds` rounds a new one opens, and when `max_windows` are open
/// neighbours are folded together first, `merge(into, from)` adding from's counts (its rounds
/// too) into into.
template <class Window, class Merge>
void end_window_round(std::vector<Window>& windows, double* window_rounds, size_t max_windows, Merge merge) {
    if (++windows.back().rounds < *window_rounds) return;
    if (windows.size() >= max_windows) {
        for (size_t i = 0; i < windows.size() / 2; ++i) {
            if (i > 0) windows[i] = std::move(windows[2 * i]);
            merge(windows[i], windows[2 * i + 1]);
        }
        windows.resize(windows.size() / 2);
        *window_rounds *= 2;
    }
    windows.emplace_back();
}

}  // namespace rtsim
