// What the user of the renderer that wrote a frame does to get a layer the frame lacks:
// the pass to enable in Blender, the film or integrator of pbrt-v4 and Mitsuba 3, our
// renderer's --layers, or `mcdenoise accumulate` for sample statistics. One table
// (hints.cpp), read by the methods' front ends when they say what a frame is missing.
#pragma once

#include <string>
#include <vector>

#include "mcdenoise/frame.h"

namespace mcd::io {

// The renderer a frame came from, as its conventions (conventions.h) and our renderer's
// metadata tell; Unknown when neither does (an accumulated frame, a hand-made one).
enum class Renderer { Ours, Blender, Pbrt, Mitsuba, Unknown };
Renderer RendererOf(const Frame &frame);

// How to get `layer` from the renderer that wrote `frame`; "" when the table has no row.
std::string HowToGet(const Frame &frame, const std::string &layer);

// `what` (e.g. "no variance layer") followed by how to get `layers` from the frame's
// renderer, each distinct hint once: what a front end's Missing() returns.
std::string Lacks(const Frame &frame, const std::string &what,
                  const std::vector<std::string> &layers);

}  // namespace mcd::io
