// Each object's light in a denoised image over the reference's, by the frame's object ids:
// a method that dims a small object (a thin highlight, a vase) shows here while the frame's
// mean brightness hardly moves. `bench real` and `bench quality` report it.
#pragma once

#include <map>
#include <string>

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

// `objects`: one channel of ids (rounded), of the output's size; anything else (an empty
// image) measures nothing.
ObjectLights MeasureObjectLights(const Image &output, const Image &reference,
                                 const Image &objects);

}  // namespace mcd::tool
