// `mcdenoise denoise`: run a method of the library (include/mcdenoise/mcdenoise.h) on a
// frame, measure it against a reference when given one, and write the result; or the
// same for every frame of a sequence (tools/mcdenoise/sequence.h) on one device
// (tools/mcdenoise/denoise_frames.h, which runs one frame as a sequence of one).
#include <fmt/format.h>

#include <cstdio>
#include <filesystem>
#include <set>
#include <variant>

#include "host/error.h"
#include "host/io/frame.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/denoise_frames.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/sequence.h"

namespace mcd::tool {
namespace {

struct DenoiseOptions {
    std::vector<std::string> inputs;
    std::string output, method = "auto", reference, preview, frames, autoMap;
    bool explain = false, overwriteInput = false, noTemporal = false;
    DeviceOptions device;
    MethodOptions methods;  // and the temporal mode's parameters
};

// One frame given as a file: its paths checked and refused before any work, as the frame
// of a sequence of one; `inPlace` set when -o is the input itself (--overwrite-input).
SequenceFrame PlanOneFrame(const DenoiseOptions &opt, bool *inPlace) {
    SequenceFrame f{0, opt.inputs.front(), opt.reference, opt.output, opt.preview, opt.autoMap};
    if (!opt.frames.empty())
        throw Error(fmt::format("--frames selects frames of a sequence; '{}' is one frame "
                                "(give a pattern such as frame.####.exr, or several files)",
                                f.input),
                    ErrorKind::InvalidArgument);
    if (!f.output.empty() &&
        (f.output.back() == '/' || std::filesystem::is_directory(f.output)))
        throw Error(
            fmt::format(
                "-o '{}' is a directory: one frame is written to a file, so give a file name "
                "ending in .exr or .png (a directory is for a sequence: frame.####.exr)",
                f.output),
            ErrorKind::InvalidArgument);
    CheckOutputPath(f.output, {".exr", ".png"});
    if (!f.preview.empty()) CheckOutputPath(f.preview, {".png"}, "--preview");
    if (!f.map.empty()) CheckOutputPath(f.map, {".png"}, "--auto-map");
    // No output may be a file this run reads, unless the user says so for -o.
    *inPlace = opt.overwriteInput && SameFile(f.output, f.input);
    if (*inPlace && LowerExtension(f.output) != ".exr")
        throw Error(
            fmt::format(
                "--overwrite-input: '{}' would lose the frame's other layers; it needs an .exr "
                "output",
                f.output),
            ErrorKind::InvalidArgument);
    RefuseOverwritingInputs(
        {{"input", *inPlace ? "" : f.input,
          "write elsewhere, or pass --overwrite-input to replace the frame's color and "
          "keep its other layers"},
         {"--reference", f.reference}},
        {{"-o", f.output}, {"--preview", f.preview}, {"--auto-map", f.map}});
    if (*inPlace)
        RefuseOverwritingInputs({{"input", f.input}},
                                {{"--preview", f.preview}, {"--auto-map", f.map}});
    return f;
}

// A sequence's paths refused before any work, and its output directories made (a farm
// task may be the first to write there) once nothing is refused.
void PrepareSequence(const std::vector<SequenceFrame> &frames) {
    std::vector<RolePath> inputs, outputs;
    for (const SequenceFrame &f : frames) {
        inputs.push_back({"input", f.input, "write the sequence elsewhere"});
        inputs.push_back({"--reference", f.reference});
        outputs.push_back({"-o", f.output});
        outputs.push_back({"--preview", f.preview});
        outputs.push_back({"--auto-map", f.map});
    }
    RefuseOverwritingInputs(inputs, outputs);
    std::set<std::string> dirs;
    for (const RolePath &out : outputs)
        if (!out.path.empty()) dirs.insert(std::filesystem::path(out.path).parent_path());
    for (const std::string &dir : dirs)
        if (!dir.empty()) PrepareDirectory(dir);
    for (const SequenceFrame &f : frames) {
        CheckOutputPath(f.output, {".exr", ".png"});
        if (!f.preview.empty()) CheckOutputPath(f.preview, {".png"}, "--preview");
        if (!f.map.empty()) CheckOutputPath(f.map, {".png"}, "--auto-map");
    }
}

// --overwrite-input keeps the file's alpha, so --alpha-rim's light cannot move with its
// coverage: it runs with 0, and says so where the command line asked for a share.
void KeepTheFilesAlpha(const DenoiseOptions &opt, Method *method) {
    float share = std::get<float>(method->Get("alpha-rim"));
    if (share > 0.f && opt.methods.Given("alpha-rim"))
        fmt::print(stderr,
                   "warning: --alpha-rim {} left out (0): --overwrite-input keeps the file's "
                   "alpha, and the rim's light without its alpha would be added over the "
                   "background; write to another file with -o for the rim\n",
                   share);
    method->Set("alpha-rim", 0.f);
}

// Another method's options are accepted (a script may change --method alone) and said to be
// unread; so are a sequence's on one frame.
void WarnUnreadOptions(const DenoiseOptions &opt, const Method &method, bool sequence) {
    Temporal temporal;
    const bool gathered = sequence && !opt.noTemporal;
    for (const ParamInfo &info : opt.methods.GivenNotTaken([&](const std::string &name) {
             return method.HasParam(name) || (gathered && temporal.HasParam(name));
         })) {
        if (temporal.HasParam(info.name))
            fmt::print(stderr, "warning: --{} is for sequences gathered in time: not read {}\n",
                       info.name, sequence ? "with --no-temporal" : "on one frame");
        else
            fmt::print(stderr, "warning: --{} is {}'s option: not read by --method {}\n",
                       info.name, info.method, opt.method);
    }
}

void RunDenoise(const DenoiseOptions &opt) {
    Method method = opt.methods.Make(opt.method);
    WarnUnreadOptions(opt, method, IsSequence(opt.inputs));
    DenoiseSettings settings;
    settings.explain = opt.explain;
    settings.device = opt.device.Options();
    if (!IsSequence(opt.inputs)) {
        settings.single = true;
        SequenceFrame frame = PlanOneFrame(opt, &settings.inPlace);
        // The file keeps its own alpha: no coverage may move beside it.
        if (settings.inPlace) KeepTheFilesAlpha(opt, &method);
        DenoiseFrames({frame}, method, settings);
        return;
    }
    if (opt.overwriteInput)
        throw Error(
            "--overwrite-input is for one frame; a sequence is written to an output pattern "
            "or directory",
            ErrorKind::InvalidArgument);
    std::vector<SequenceFrame> frames = PlanSequence(
        {opt.inputs, opt.output, opt.preview, opt.reference, opt.frames, opt.autoMap});
    PrepareSequence(frames);
    // The frames of one shot: each gathered with its neighbours unless told otherwise.
    Temporal temporal;
    opt.methods.Apply(temporal);
    if (!opt.noTemporal) settings.temporal = &temporal;
    DenoiseFrames(frames, method, settings);
}

}  // namespace

void AddDenoiseCommand(CLI::App &app) {
    auto opt = std::make_shared<DenoiseOptions>();
    CLI::App *cmd = app.add_subcommand(
        "denoise",
        "Denoise a frame or a sequence of frames (method auto by default)\n\nMethods "
        "(--method):" +
            MethodOptions::Summaries());
    cmd->add_option("input", opt->inputs,
                    "noisy frame (EXR with the layers the method needs); for a sequence, "
                    "several frames or one pattern (frame.####.exr or frame.%04d.exr)")
        ->required();
    cmd->add_option("-o,--output", opt->output,
                    "denoised image (.exr or .png); for a sequence, a pattern "
                    "(out.####.exr) or a directory (out/)")
        ->required();
    cmd->add_option("--method", opt->method,
                    "auto (the default: its candidates that the frame's layers allow, combined "
                    "per pixel; nfor alone on a frame without statistics), " +
                        MethodOptions::Names())
        ->capture_default_str();
    cmd->add_flag("--explain", opt->explain, "print what runs and what is left out, and why");
    cmd->add_option("--reference", opt->reference,
                    "converged image to measure the error against, before and after (for a "
                    "sequence, a pattern or one image for every frame)");
    cmd->add_option("--preview", opt->preview,
                    "also write a tonemapped PNG (for a sequence, a pattern or a directory)");
    cmd->add_option("--auto-map", opt->autoMap,
                    "auto: write the map of the largest weights as a PNG here, each pixel "
                    "coloured by the candidate with the largest weight (--explain gives the "
                    "colours); for a sequence, a pattern (map.####.png) or a directory");
    cmd->add_option("--frames", opt->frames,
                    "the frames of a sequence to denoise: N, FIRST-LAST or a list of those "
                    "(1-50,60); a pattern's frame missing on disk fails that frame");
    cmd->add_flag("--overwrite-input", opt->overwriteInput,
                  "let -o be the input frame (.exr): the result replaces the renderer's "
                  "colour (Blender: Combined), the noisy colour is kept (Blender: as Noisy "
                  "Image; else as " +
                      std::string(io::kNoisyColorLayer) +
                      ") and every other channel as it was, under its own name");
    cmd->add_flag("--no-temporal", opt->noTemporal,
                  "a sequence: denoise each frame alone (by default each frame is gathered "
                  "with its neighbours, --temporal-radius frames before and after, through "
                  "the frames' motion vectors where they have them)");
    opt->device.Add(cmd);
    opt->methods.Add(cmd);
    opt->methods.AddParams(cmd, Temporal().Params());
    cmd->footer(
        "Progress goes to stderr: redrawn on a terminal, else a line every "
        "$MCD_PROGRESS_SECONDS (5) seconds.");
    cmd->callback([opt] { RunDenoise(*opt); });
}

}  // namespace mcd::tool
