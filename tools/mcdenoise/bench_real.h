// `mcdenoise bench real`: the measurements on a set of real renders (the scenes
// scripts/blender/realset.sh writes) and the report written from them.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "host/metrics.h"
#include "mcdenoise/image.h"
#include "tools/mcdenoise/object_light.h"

namespace mcd::tool {

// One output measured against its scene's reference: the input itself ("input"), a
// method, auto, or a peer ("oidn", "oidn color").
struct RealRow {
    std::string scene, frame, method;  // frame: "plain" or "accumulated"
    std::string refused;               // why the method did not run on the frame
    ErrorMetrics error;   // with the mean brightness of the output over the reference's
    double worst = 0;     // mean relMSE term of the worst 1% of pixels
    ObjectLights lights;  // each object's light, where the scene has ids
    double seconds = -1;  // denoise wall time; negative for the input
    std::string note;     // e.g. what auto ran
    std::string png;      // the output's preview, relative to the report directory

    bool Ran() const { return refused.empty(); }
};

// A scene's reference and its own noise: relMSE of the mean of two halves against the
// truth, estimated as mean((a - b)^2 / 4 / (r^2 + 0.01)).
struct RealScene {
    std::string name;
    Image reference;
    double referenceNoise = -1;  // negative when the reference has no halves
    int referenceSpp = 0;
    std::string referenceFrom;  // ref.exr, or the chunks it was assembled from
    std::string referencePng;
    // Object ids and coverage from the scene's frames, for the objects' light; no ids when
    // neither frame has an objectId layer.
    ObjectMap objects;
};

// Where the Open Image Denoise peer is looked for when no --oidn is given: $MCDENOISE_OIDN,
// else ../shared/peers/oidn (beside the repository, for a run from its root).
std::string DefaultOidnPeer();

// The figures beyond CompareImages': the mean relMSE term of the worst 1% of pixels, and
// where `objects` holds ids (not empty), each object's light over the reference's.
void MeasureRow(const Image &output, const Image &reference, const ObjectMap &objects,
                RealRow *row);

// The objects of a scene's folder: the objectId layer of acc.exr, else of plain.exr, with
// that file's alpha where it has one; no ids when neither has an objectId layer.
ObjectMap LoadObjects(const std::string &sceneDir);

// relMSE the reference carries: from its two halves, the means of count0 and count1
// chunks (frames) of equal spp and different seeds.
double ReferenceNoise(const Image &half0, const Image &half1, const Image &reference,
                      int count0, int count1);

// The reference chunks of a scene's folder, <dir>/ref/chunkNN.exr, sorted.
std::vector<std::string> ReferenceChunks(const std::string &sceneDir);

// Whether a scene's folder has a reference: ref.exr, or two chunks or more.
bool HasReference(const std::string &sceneDir);

// The scene's reference: <set>/<name>/ref.exr when it holds every chunk present (no older
// than any, made from as many), else the mean of the chunks (two or more); its spp and
// its own noise from its halves.
RealScene LoadScene(const std::string &set, const std::string &name);

// The images side by side, `gap` black pixels apart (all of one height).
Image MakeStrip(const std::vector<Image> &images, int gap);

// Write <out>/real.csv, real.md, index.html and the strips (<scene>-<frame>.png); print the
// Markdown summary. `header` describes the run (device, set, peer).
void WriteRealReport(const std::string &out, const std::string &header,
                     const std::vector<RealScene> &scenes, const std::vector<RealRow> &rows);

}  // namespace mcd::tool
