// mcdenoise: denoise Monte Carlo renders with the methods of four papers (Ray Histogram
// Fusion, Adaptive Wavelet Rendering, Bayesian wavelet shrinkage, the pivot-image filter),
// run as Vulkan compute kernels. The object model follows Open Image Denoise: a device, a
// method created by name, typed parameters, a frame of named layers, a run.
//
//     mcd::Device device;                       // the best Vulkan device ($MCD_DEVICE)
//     mcd::Frame frame = mcd::ReadFrame("frame.exr");
//     mcd::Method method("auto");               // or awr, bayes, pivot, rhf
//     method.Set("kappa", 0.6f);                // typed; checked against the table
//     mcd::Result result = method.Run(device, frame);
//     mcd::WriteExr("out.exr", {{"color", &result.image}});
//
// Every failure is an mcd::Error whose message says what and where. No Vulkan type appears
// here.
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
    std::string method;                   // the method that ran ("auto" resolves to one)
    Image image;                          // the denoised color, the frame's size and channels
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
    // Called as long stages advance: (stage, done, total).
    std::function<void(const std::string &stage, int done, int total)> progress;
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
