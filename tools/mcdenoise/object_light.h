// Each object's light in a denoised image over the reference's, by the frame's object ids:
// a method that dims a small object (a thin highlight, a vase) shows here while the frame's
// mean brightness hardly moves. `bench real` and `bench quality` report it.
#pragma once

#include <map>
#include <string>

#include "mcdenoise/frame.h"
#include "mcdenoise/image.h"

namespace mcd::tool {

// Objects smaller than this many pixels are not measured on their own: their light is
// too few pixels' noise.
inline constexpr int kObjectPixels = 64;

// An object's light in an output over the reference's: Rec. 709 luminance summed over the
// pixels of its id.
struct ObjectLight {
    int pixels = 0;
    double ratio = 1;
};

// The measured objects (kObjectPixels or more, of light in the reference) by id, and the
// darkest of them (-1: none; a non-finite output's NaN ranks darkest).
struct ObjectLights {
    std::map<int, ObjectLight> objects;
    int darkestId = -1;

    // The darkest object's light over the reference's; NaN where none was measured.
    double Darkest() const;
};

// The CSV fields darkest_object,darkest_object_id ("," where none was measured).
std::string DarkestCsv(const ObjectLights &lights);

// Where a frame's objects lie: one channel of ids (rounded) and, where the frame has one,
// its coverage (alpha). An id most of whose pixels are empty (alpha 0: a transparent film's
// background) is no object: what light it holds is the rims of the objects in front.
struct ObjectMap {
    Image ids;
    Image coverage;  // empty: every pixel covered
};

// A frame's objectId layer (none: no ids) and its alpha where it has one.
ObjectMap ObjectsOf(const Frame &frame);

// `objects.ids` of the output's size; anything else (an empty image) measures nothing, and
// a coverage of another size is not read.
ObjectLights MeasureObjectLights(const Image &output, const Image &reference,
                                 const ObjectMap &objects);

}  // namespace mcd::tool
