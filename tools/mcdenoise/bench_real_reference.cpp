// `mcdenoise bench real`: a scene's reference, from its ref.exr or from the chunks
// realset.sh renders into ref/ (the newest state of the set, while chunks are being added),
// and the reference's own noise from two halves of different seeds.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <regex>

#include "host/error.h"
#include "host/io/accumulate.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/bench_real.h"

namespace mcd::tool {
namespace {

namespace fs = std::filesystem;

// The accumulated frames ref.exr states, or 0 when it states none.
int AccumulatedFrames(const std::map<std::string, std::string> &metadata) {
    auto it = metadata.find("mcd:accumulatedFrames");
    return it == metadata.end() ? 0 : std::atoi(it->second.c_str());
}

// Whether ref.exr holds every chunk: it is no older than any and was made from as many
// (realset.sh accumulates the chunks into it; a chunk added later makes it stale).
bool ReferenceFileCurrent(const fs::path &file, const std::vector<std::string> &chunks) {
    std::error_code ec;
    if (!fs::exists(file, ec)) return false;
    if (chunks.empty()) return true;
    fs::file_time_type made = fs::last_write_time(file, ec);
    for (const std::string &chunk : chunks)
        if (fs::last_write_time(chunk, ec) > made) return false;
    return AccumulatedFrames(io::ReadFrameHeader(file.string()).metadata) == int(chunks.size());
}

// The reference as the mean of the chunks' colour, and its halves: the means of the odd
// and of the even chunks (accumulate's split, so both ways give the same reference).
void AssembleFromChunks(const std::vector<std::string> &chunks, RealScene *scene) {
    Image sum[2];
    int counts[2] = {0, 0}, spp = 0;
    for (size_t i = 0; i < chunks.size(); ++i) {
        Image color = ReadImage(chunks[i], "color");
        Image &half = sum[i % 2];
        if (half.Size() == 0) half = Image(color.width, color.height, 3);
        if (color.channels < 3 || !color.SameShape(sum[0]))
            throw Error(
                fmt::format("'{}' is not an RGB image of {}'s size", chunks[i], chunks.front()),
                ErrorKind::InvalidArgument);
        for (size_t j = 0; j < half.Size(); ++j) half.data[j] += color.data[j];
        ++counts[i % 2];
        int chunkSpp = io::SppFromMetadata(io::ReadFrameHeader(chunks[i]).metadata);
        spp = spp >= 0 && chunkSpp > 0 ? spp + chunkSpp : -1;
    }
    scene->reference = Image(sum[0].width, sum[0].height, 3);
    for (size_t j = 0; j < scene->reference.Size(); ++j)
        scene->reference.data[j] =
            float((double(sum[0].data[j]) + sum[1].data[j]) / double(counts[0] + counts[1]));
    for (int h = 0; h < 2; ++h)
        for (float &v : sum[h].data) v = float(double(v) / counts[h]);
    scene->referenceNoise =
        ReferenceNoise(sum[0], sum[1], scene->reference, counts[0], counts[1]);
    scene->referenceSpp = std::max(spp, 0);
    scene->referenceFrom = fmt::format("the mean of {} chunks in ref/", chunks.size());
}

}  // namespace

double ReferenceNoise(const Image &half0, const Image &half1, const Image &reference,
                      int count0, int count1) {
    if (!half0.SameShape(reference) || !half1.SameShape(reference))
        throw Error("the reference's halves and its color differ in size",
                    ErrorKind::InvalidArgument);
    // The reference, (n0 a + n1 b) / (n0 + n1), has the variance of a - b times
    // n0 n1 / (n0 + n1)^2 (a quarter for equal halves).
    double share = double(count0) * count1 / (double(count0 + count1) * (count0 + count1));
    int channels = std::min(reference.channels, 3);
    double sum = 0;
    size_t count = 0;
    for (int c = 0; c < channels; ++c)
        for (int y = 0; y < reference.height; ++y)
            for (int x = 0; x < reference.width; ++x) {
                double a = half0.At(c, y, x), b = half1.At(c, y, x), r = reference.At(c, y, x);
                if (!std::isfinite(a) || !std::isfinite(b) || !std::isfinite(r)) continue;
                sum += (a - b) * (a - b) * share / (r * r + 0.01);
                ++count;
            }
    return count ? sum / double(count) : NAN;
}

std::vector<std::string> ReferenceChunks(const std::string &sceneDir) {
    std::vector<std::string> chunks;
    std::error_code ec;
    fs::path dir = fs::path(sceneDir) / "ref";
    if (!fs::is_directory(dir, ec)) return chunks;
    static const std::regex name("chunk[0-9]+\\.exr");
    for (const fs::directory_entry &entry : fs::directory_iterator(dir, ec))
        if (entry.is_regular_file() && std::regex_match(entry.path().filename().string(), name))
            chunks.push_back(entry.path().string());
    std::sort(chunks.begin(), chunks.end());
    return chunks;
}

bool HasReference(const std::string &sceneDir) {
    std::error_code ec;
    return fs::exists(fs::path(sceneDir) / "ref.exr", ec) ||
           ReferenceChunks(sceneDir).size() >= 2;
}

ObjectMap LoadObjects(const std::string &sceneDir) {
    for (const char *file : {"acc.exr", "plain.exr"}) {
        fs::path path = fs::path(sceneDir) / file;
        std::error_code ec;
        if (!fs::exists(path, ec)) continue;
        Frame frame = ReadFrame(path.string(), {{"objectId", "alpha"}});
        if (frame.Has("objectId")) return ObjectsOf(frame);
    }
    return {};
}

RealScene LoadScene(const std::string &set, const std::string &name) {
    fs::path dir = fs::path(set) / name, file = dir / "ref.exr";
    std::vector<std::string> chunks = ReferenceChunks(dir.string());
    RealScene scene;
    scene.name = name;
    if (!ReferenceFileCurrent(file, chunks)) {
        if (chunks.size() < 2)
            throw Error(fmt::format("{}: {} is older than its chunks and there are fewer than "
                                    "two chunks to make a reference of",
                                    name, file.string()),
                        ErrorKind::InvalidArgument);
        AssembleFromChunks(chunks, &scene);
        return scene;
    }
    Frame frame = ReadFrame(file.string());
    scene.reference = frame.Get("color");
    scene.referenceFrom = file.string();
    if (frame.Has("half0.color") && frame.Has("half1.color")) {
        // accumulate puts frames 0, 2, ... in half0: it holds the odd one out.
        int frames = std::max(AccumulatedFrames(frame.metadata), 2);
        scene.referenceNoise =
            ReferenceNoise(frame.Get("half0.color"), frame.Get("half1.color"), scene.reference,
                           (frames + 1) / 2, frames / 2);
    }
    if (auto it = frame.metadata.find("mcd:spp"); it != frame.metadata.end())
        scene.referenceSpp = std::atoi(it->second.c_str());
    return scene;
}

}  // namespace mcd::tool
