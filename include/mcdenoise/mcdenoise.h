// mcdenoise: denoise Monte Carlo renders with the methods of four papers (Ray Histogram
// Fusion, Adaptive Wavelet Rendering, Bayesian wavelet shrinkage, the pivot-image filter),
// run as Vulkan compute kernels. The object model follows Open Image Denoise: a device, a
// method created by name, typed parameters, a frame of named layers, a run.
//
//     mcd::Device device;                       // the best Vulkan device ($MCD_DEVICE)
//     mcd::Frame frame;                         // the renderer's buffers, borrowed
//     frame.SetLayer("color", mcd::LayerView::Interleaved(rgb, width, height, 3));
//     frame.SetLayer("albedo", mcd::LayerView::Interleaved(albedo, width, height, 3));
//     mcd::Method method("auto");               // or awr, bayes, pivot, rhf
//     method.Set("kappa", 0.6f);                // typed; checked against the table
//     mcd::RunOptions run;
//     run.output = mcd::OutputView::Interleaved(out, width, height, 3);
//     mcd::Result result = method.Run(device, frame, run);   // the result is in `out`
//
// Files: mcdenoise/io.h (ReadFrame, WriteExr; library mcdenoise::io). C: mcdenoise_c.h.
// Every failure is an mcd::Error whose message says what and where and whose Kind() says
// what sort of failure it is. No Vulkan type appears here; the header is C++17.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "mcdenoise/error.h"
#include "mcdenoise/frame.h"
#include "mcdenoise/image.h"
#include "mcdenoise/view.h"

namespace mcd {

struct DeviceOptions {
    // Device index or case-insensitive name substring; empty: $MCD_DEVICE, then the best
    // device (discrete, integrated, virtual, CPU).
    std::string device;
    // Khronos validation layer; its messages are collected (TakeValidationMessages).
    bool validation = false;
    // A file for the driver's pipeline cache (VkPipelineCache): read at the start, written
    // back at the end when pipelines were built, so a later process builds them faster
    // where the driver honours it. Empty: none.
    std::string pipelineCache;
};

// A Vulkan device with its queue and the kernels built on it so far. Pipelines are built on
// first use and kept, so a second run on the same device is cheaper than the first.
class Device {
  public:
    explicit Device(const DeviceOptions &options = {});
    ~Device();
    Device(Device &&) noexcept;
    Device &operator=(Device &&) noexcept;

    std::string Name() const;
    // Validation messages since the last call.
    std::vector<std::string> TakeValidationMessages();

  private:
    struct Impl;
    friend struct DeviceAccess;  // the library's own tools and tests (internal)
    explicit Device(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl;
};

enum class ParamType { Bool, Int, Float, String };
using ParamValue = std::variant<bool, int, float, std::string>;

// One typed parameter of a method: its name (also the command line's --name), what it
// means, its default, and the values it takes.
struct ParamInfo {
    std::string name;
    ParamType type = ParamType::Float;
    std::string help;
    ParamValue defaultValue;
    double min = 0, max = 0;           // Int and Float: the closed range
    std::vector<std::string> choices;  // String: the values taken (empty: any)
    std::string method;                // which method it belongs to ("" for every method)
};

// A GPU dispatch's label and time (negative where the device has no timestamps).
struct Timing {
    std::string label;
    double gpuMs = 0;
};

// One intermediate image of a run, by the stage name the GPU and CPU reference share.
struct Stage {
    std::string name;
    Image image;
};

struct Allocation {
    std::string name;
    uint64_t bytes = 0;
};

struct Result {
    // The method that ran: the Method's name, except that auto gives "auto" when it combined
    // its candidates (listed in `candidates`) and the one method it picked when it picked
    // one (with demodulate; nfor on a frame without statistics).
    std::string method;
    std::vector<std::string> candidates;  // auto: the candidates it combined, as it ran them
    // The denoised color, the frame's size and channels; empty when RunOptions::output
    // received it.
    Image image;
    Image alpha;  // the frame's alpha layer, alpha-rim's shares moved (empty: none)
    // Pixels of alpha 0 that took alpha-rim's shares of their covered neighbours: light
    // and alpha moved there together, so `image` is only right over a background
    // composited with `alpha` (a 3-channel copy of it would light the background).
    int rimPixels = 0;
    std::vector<std::string> plan;        // what ran, what was left out, and why
    std::vector<std::string> warnings;    // e.g. non-finite input values replaced
    std::vector<Stage> stages;            // with RunOptions::keepStages
    std::vector<Timing> timings;          // per dispatch
    std::vector<Allocation> allocations;  // GPU buffers, in order of allocation
    uint64_t peakBytes = 0;               // GPU memory held at most (staging not counted)
    double wallMs = 0;                    // the run, uploads and downloads included

    double GpuMs() const;
};

struct RunOptions {
    // Download every stage's image into Result::stages (slower: a submission per stage).
    bool keepStages = false;
    // Stages to return by name without keepStages, of those a method makes on request:
    // auto's "auto.map" (each pixel coloured by the candidate of the largest weight; the
    // plan names the colours). Another name, or another method, returns none. A run in
    // tiles assembles them from its tiles.
    std::vector<std::string> stages;
    // Called as long stages advance: (stage, done, total): tiles, pivot's row strips.
    std::function<void(const std::string &stage, int done, int total)> progress;
    // Polled before each GPU submission (so between dispatch batches, stages, tiles and
    // auto's candidates); once it returns true the run stops: Run throws mcd::Error of kind
    // Cancelled and writes nothing to `output`. A submission under way runs to its end.
    std::function<bool()> cancel;
    // Where the result goes (no data: Result::image). The frame's width and height, with
    // the color's channels or one more, which receives Result::alpha (1 where the frame has
    // none). Without that channel alpha-rim does not run (the plan says so): its moved alpha
    // would not reach the caller. Written only when the run succeeds; Result::image is
    // then left empty.
    OutputView output;
    // Internal (tests): run in tiles of this many pixels a side, with the method's halo,
    // even where the frame fits the device. 0: tiles only where it does not fit.
    int tileSize = 0;
};

// A denoising method created by name. Parameters start at their measured defaults; Set
// checks name, type and range. Copies are independent.
class Method {
  public:
    explicit Method(const std::string &name);
    ~Method();
    Method(const Method &other);
    Method &operator=(const Method &other);
    Method(Method &&) noexcept;
    Method &operator=(Method &&) noexcept;

    const std::string &Name() const;
    std::string Summary() const;
    const std::vector<ParamInfo> &Params() const;

    void Set(const std::string &name, ParamValue value);
    void Set(const std::string &name, bool value) { Set(name, ParamValue(value)); }
    void Set(const std::string &name, int value) { Set(name, ParamValue(value)); }
    void Set(const std::string &name, float value) { Set(name, ParamValue(value)); }
    void Set(const std::string &name, double value);
    void Set(const std::string &name, const char *value) { Set(name, std::string(value)); }
    void Set(const std::string &name, const std::string &text) { Set(name, ParamValue(text)); }
    // Parse `text` as the parameter's type ("0.5", "true", "swt").
    void SetText(const std::string &name, const std::string &text);
    ParamValue Get(const std::string &name) const;
    bool HasParam(const std::string &name) const;

    // The layers a run may read, for ReadOptions::layers (empty: any): the method's own,
    // color, alpha and what --demodulate divides by. Changes with the parameters.
    std::vector<std::string> Uses() const;

    // Why this method cannot run on the frame with its parameters ("" when it can).
    std::string Missing(const Frame &frame) const;

    Result Run(Device &device, const Frame &frame, const RunOptions &options = {}) const;

    // The CPU reference's stages on the frame, same parameters, named as the GPU run's
    // with keepStages (what `mcdenoise diff` compares).
    std::vector<Stage> Reference(Device &device, const Frame &frame) const;

    struct Impl;

  private:
    std::unique_ptr<Impl> impl;
};

// The methods, in the order the command line lists them; "auto" is not among them.
std::vector<std::string> MethodNames();

// The library's version, "major.minor.patch".
const char *Version();

}  // namespace mcd
