// `mcdenoise bench real`: every method and auto, and Open Image Denoise where it is present
// (a peer to measure against, never a dependency), on a set of real renders: per scene a
// plain frame with what a user has and an accumulated frame with statistics, each against
// the scene's many-spp reference (scripts/blender/realset.sh renders the set). Runs the
// library API as `bench quality` does; CSV, Markdown and an HTML page with a strip per
// scene and frame.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <regex>
#include <set>
#include <sstream>

#include "host/error.h"
#include "mcdenoise/io.h"
#include "tools/mcdenoise/bench_real.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/usage.h"

namespace mcd::tool {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct BenchRealOptions {
    std::string set, scenes = "all", methods = "all", out = "out/bench-real", oidn;
    bool noOidn = false;
    int oidnRuns = 3;
    DeviceOptions device;
    MethodOptions methodOptions;
};

// The frames a scene of the set holds, by the name the report gives them.
struct FrameFile {
    const char *kind, *file;
};
constexpr FrameFile kFrames[] = {{"plain", "plain.exr"}, {"accumulated", "acc.exr"}};

std::string DefaultSet() {
    const char *home = std::getenv("HOME");
    return (fs::path(home ? home : ".") / ".cache/mcdenoise/realset").string();
}

std::vector<std::string> SplitList(const std::string &text) {
    std::vector<std::string> items;
    std::stringstream stream(text);
    for (std::string item; std::getline(stream, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

// The scenes of the set: its folders with a reference (ref.exr or two chunks in ref/),
// sorted; or those listed, each of which must have one.
std::vector<std::string> SetScenes(const std::string &set, const std::string &scenes) {
    std::error_code ec;
    if (!fs::is_directory(set, ec))
        throw Error(fmt::format("'{}' is not a directory of scenes (render one with "
                                "scripts/blender/realset.sh --out DIR)",
                                set),
                    ErrorKind::InvalidArgument);
    std::vector<std::string> names;
    if (scenes != "all") {
        for (const std::string &name : SplitList(scenes)) {
            fs::path dir = fs::path(set) / name;
            if (!HasReference(dir.string()))
                throw Error(
                    fmt::format("--scenes: '{}' has neither {} nor two chunks {}", name,
                                (dir / "ref.exr").string(), (dir / "ref/chunkNN.exr").string()),
                    ErrorKind::InvalidArgument);
            names.push_back(name);
        }
        return names;
    }
    for (const fs::directory_entry &entry : fs::directory_iterator(set))
        if (entry.is_directory() && HasReference(entry.path().string()))
            names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    if (names.empty())
        throw Error(fmt::format("'{}' has no scene folder with a reference (realset.sh writes "
                                "<scene>/ref/chunkNN.exr and <scene>/ref.exr)",
                                set),
                    ErrorKind::InvalidArgument);
    return names;
}

std::string PngName(const std::string &scene, const std::string &frame,
                    const std::string &method) {
    std::string name = fmt::format("{}-{}-{}.png", scene, frame, method);
    std::replace(name.begin(), name.end(), ' ', '_');
    return name;
}

std::string ShellQuote(const std::string &text) {
    std::string quoted = "'";
    for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return quoted + "'";
}

// The peer on one frame file: its output and the filter's own time (median over runs) as
// its README's script prints it. Throws mcd::Error with the script's last lines.
Image RunOidn(const std::string &oidn, const std::string &input, const std::string &output,
              bool aux, int runs, double *seconds) {
    std::string command =
        fmt::format("/usr/bin/python3 {} {} {} {} --runs {} 2>&1",
                    ShellQuote((fs::path(oidn) / "denoise_exr.py").string()), ShellQuote(input),
                    ShellQuote(output), aux ? "--aux" : "", runs);
    FILE *pipe = popen(command.c_str(), "r");
    if (!pipe) throw Error("cannot start " + command, ErrorKind::Io);
    std::string log;
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) log += buffer;
    int status = pclose(pipe);
    if (status != 0 || !fs::exists(output)) {
        // Its last two lines, whole: the loader's or the script's own complaint.
        std::vector<std::string> lines;
        std::istringstream stream(log);
        for (std::string line; std::getline(stream, line);)
            if (size_t start = line.find_first_not_of(" \t"); start != std::string::npos)
                lines.push_back(line.substr(start));
        std::string tail;
        for (size_t k = lines.size() > 2 ? lines.size() - 2 : 0; k < lines.size(); ++k)
            tail += (tail.empty() ? "" : " / ") + lines[k];
        throw Error(
            fmt::format("{}{} on {} failed: {}", (fs::path(oidn) / "denoise_exr.py").string(),
                        aux ? " --aux" : "", input, tail),
            ErrorKind::Io);
    }
    std::smatch match;
    static const std::regex median("median ([0-9.eE+-]+) ms");
    *seconds = std::regex_search(log, match, median) ? std::stod(match[1]) * 1e-3 : -1;
    return ReadImage(output, "color");
}

}  // namespace

namespace {

// What one frame of a scene gives the report: its rows, and its previews for the strip.
struct FrameRun {
    const RealScene &scene;
    std::string kind, path, out;
    std::vector<RealRow> rows;
    std::vector<Image> strip;
};

void AddMeasured(FrameRun &run, const std::string &method, Image output, double seconds,
                 const std::string &note) {
    RealRow row{run.scene.name, run.kind, method};
    row.error = CompareImages(output, run.scene.reference);
    MeasureRow(output, run.scene.reference, run.scene.objects, &row);
    row.seconds = seconds;
    row.note = note;
    row.png = PngName(run.scene.name, run.kind, method);
    WritePng((fs::path(run.out) / row.png).string(), output);
    fmt::print(
        "  {:<20} {:<11} {:<10} relMSE {:<10.4g} PSNR {:6.2f} SSIM {:.4f} mean {:.3f} "
        "worst1% {:<9.4g} {}{}\n",
        run.scene.name, run.kind, method, row.error.relMse, row.error.psnr, row.error.ssim,
        row.error.brightness, row.worst,
        row.lights.darkestId >= 0 ? fmt::format("darkest object {:.3f} ({}) ",
                                                row.lights.Darkest(), row.lights.darkestId)
                                  : "",
        seconds >= 0 ? fmt::format("{:.3f} s", seconds) : "");
    std::fflush(stdout);
    run.rows.push_back(std::move(row));
    run.strip.push_back(std::move(output));
}

void AddRefused(FrameRun &run, const std::string &method, const std::string &why) {
    RealRow row{run.scene.name, run.kind, method, why};
    fmt::print("  {:<20} {:<11} {:<10} refused: {}\n", run.scene.name, run.kind, method, why);
    run.rows.push_back(std::move(row));
}

std::string Joined(const std::vector<std::string> &lines) {
    std::string text;
    for (const std::string &line : lines) text += (text.empty() ? "" : "; ") + line;
    return text;
}

// Each method on the frame, timed after an untimed run that builds its kernels.
void RunMethods(Device &device, const std::vector<Method> &methods, std::set<std::string> &warm,
                const Frame &frame, FrameRun &run) {
    for (const Method &method : methods) {
        std::string why = method.Missing(frame);
        if (!why.empty()) {
            AddRefused(run, method.Name(), why);
            continue;
        }
        try {
            if (!warm.count(method.Name())) {
                method.Run(device, frame);
                warm.insert(method.Name());
            }
            Clock::time_point start = Clock::now();
            Result result = method.Run(device, frame);
            double seconds = std::chrono::duration<double>(Clock::now() - start).count();
            // auto's own plan lines say what it ran and left out.
            std::vector<std::string> notes;
            for (const std::string &line : result.plan)
                if (method.Name() == "auto" && line.rfind("auto: ", 0) == 0)
                    notes.push_back(line);
            notes.insert(notes.end(), result.warnings.begin(), result.warnings.end());
            std::string note = Joined(notes);
            AddMeasured(run, method.Name(), std::move(result.image), seconds, note);
        } catch (const Error &e) {
            AddRefused(run, method.Name(), e.what());
        }
    }
}

// The peer with color, albedo and normal, and with color only, on the frame's file.
void RunPeer(const std::string &oidn, int runs, FrameRun &run) {
    for (bool aux : {true, false}) {
        std::string method = aux ? "oidn" : "oidn color";
        std::string output =
            (fs::path(run.out) /
             fmt::format("{}-{}-{}.exr", run.scene.name, run.kind, aux ? "oidn" : "oidn_color"))
                .string();
        try {
            double seconds = -1;
            Image image = RunOidn(oidn, run.path, output, aux, runs, &seconds);
            AddMeasured(run, method, std::move(image), seconds,
                        aux ? "color, albedo, normal; filter time" : "color; filter time");
        } catch (const Error &e) {
            AddRefused(run, method, e.what());
        }
    }
}

std::vector<Method> ChosenMethods(const BenchRealOptions &opt) {
    std::vector<std::string> names = MethodNames(), listed = SplitList(opt.methods);
    names.push_back("auto");
    for (const std::string &name : listed)
        if (opt.methods != "all" && std::find(names.begin(), names.end(), name) == names.end())
            throw Error(fmt::format("--methods: unknown method '{}' (methods: {}, auto)", name,
                                    MethodOptions::Names()),
                        ErrorKind::InvalidArgument);
    std::vector<Method> methods;
    for (const std::string &name : names)
        if (opt.methods == "all" ||
            std::find(listed.begin(), listed.end(), name) != listed.end())
            methods.push_back(opt.methodOptions.Make(name));
    return methods;
}

}  // namespace

std::string DefaultOidnPeer() {
    const char *peer = std::getenv("MCDENOISE_OIDN");
    return peer && *peer ? peer : "../shared/peers/oidn";
}

namespace {

// The peer's directory: --oidn (which must hold its script), else the shared copy when
// present and not --no-oidn; "" for none.
std::string PeerDirectory(const BenchRealOptions &opt) {
    if (!opt.oidn.empty()) {
        if (!fs::exists(fs::path(opt.oidn) / "denoise_exr.py"))
            throw Error(fmt::format("--oidn '{}': no denoise_exr.py there (the Open Image "
                                    "Denoise peer's README)",
                                    opt.oidn),
                        ErrorKind::InvalidArgument);
        return opt.oidn;
    }
    std::string peer = DefaultOidnPeer();
    if (opt.noOidn || !fs::exists(fs::path(peer) / "denoise_exr.py")) return "";
    return peer;
}

void RunBenchReal(const BenchRealOptions &opt) {
    std::string set = opt.set.empty() ? DefaultSet() : opt.set;
    std::vector<std::string> names = SetScenes(set, opt.scenes);
    std::vector<Method> methods = ChosenMethods(opt);
    std::string oidn = PeerDirectory(opt);
    std::vector<RolePath> inputs, outputs;
    for (const std::string &name : names)
        for (const char *file : {"ref.exr", "plain.exr", "acc.exr"})
            inputs.push_back({"input", (fs::path(set) / name / file).string(), ""});
    for (const std::string &name : names)
        for (const std::string &chunk : ReferenceChunks((fs::path(set) / name).string()))
            inputs.push_back({"input", chunk, ""});
    for (const char *file : {"real.csv", "real.md", "index.html"})
        outputs.push_back({"-o", (fs::path(opt.out) / file).string(), ""});
    RefuseOverwritingInputs(inputs, outputs);
    PrepareDirectory(opt.out);

    Device device(opt.device.Options());
    std::string header = fmt::format(
        "set {}, {} scene(s); methods on {}; peer: {}", set, names.size(), device.Name(),
        oidn.empty() ? "none" : "Open Image Denoise (" + oidn + ", CPU)");
    fmt::print("bench real: {}\n", header);
    std::vector<RealScene> scenes;
    std::vector<RealRow> rows;
    std::set<std::string> warm;
    for (const std::string &name : names) {
        scenes.push_back(LoadScene(set, name));
        scenes.back().objects = LoadObjects((fs::path(set) / name).string());
        const RealScene &scene = scenes.back();
        scenes.back().referencePng = PngName(name, "reference", "color");
        WritePng((fs::path(opt.out) / scene.referencePng).string(), scene.reference);
        fmt::print("{}: reference {} spp ({}), its own relMSE noise {}\n", name,
                   scene.referenceSpp, scene.referenceFrom,
                   scene.referenceNoise >= 0 ? fmt::format("{:.3g}", scene.referenceNoise)
                                             : "unknown (no half0.color, half1.color)");
        for (const FrameFile &f : kFrames) {
            FrameRun run{scene, f.kind, (fs::path(set) / name / f.file).string(), opt.out};
            if (!fs::exists(run.path)) {
                AddRefused(run, "input", "no " + run.path);
                rows.insert(rows.end(), run.rows.begin(), run.rows.end());
                continue;
            }
            Frame frame = ReadFrame(run.path);
            AddMeasured(run, "input", frame.Get("color"), -1, "");
            RunMethods(device, methods, warm, frame, run);
            if (!oidn.empty()) RunPeer(oidn, opt.oidnRuns, run);
            run.strip.push_back(scene.reference);
            WritePng((fs::path(opt.out) / fmt::format("{}-{}.png", name, f.kind)).string(),
                     MakeStrip(run.strip, 4));
            rows.insert(rows.end(), run.rows.begin(), run.rows.end());
        }
    }
    WriteRealReport(opt.out, header, scenes, rows);
}

}  // namespace

void AddBenchRealCommand(CLI::App *bench) {
    auto opt = std::make_shared<BenchRealOptions>();
    CLI::App *real = bench->add_subcommand(
        "real",
        "Every method, auto and Open Image Denoise on a set of real renders\n\n"
        "Per scene of the set (scripts/blender/realset.sh renders one), its plain frame (what "
        "a user has) and its accumulated frame against the scene's reference; relMSE, PSNR, "
        "SSIM, mean brightness over the reference's, the worst 1% of pixels, each object's "
        "light (the frames' objectId layer), time; CSV, "
        "Markdown and an HTML page with a strip per scene. Open Image Denoise, where present, "
        "is a peer to measure against.");
    real->add_option("set", opt->set,
                     "the set's directory, one folder per scene with plain.exr, acc.exr and "
                     "ref.exr or ref/chunkNN.exr, the mean of those chunks where ref.exr is "
                     "missing or older (default: ~/.cache/mcdenoise/realset)");
    real->add_option("--scenes", opt->scenes, "comma-separated scenes, or all")
        ->capture_default_str();
    real->add_option("--methods", opt->methods, "comma-separated methods (and auto), or all")
        ->capture_default_str();
    real->add_option("--oidn", opt->oidn,
                     fmt::format("Open Image Denoise peer directory with denoise_exr.py "
                                 "(default: {} when present; $MCDENOISE_OIDN sets it)",
                                 DefaultOidnPeer()));
    real->add_flag("--no-oidn", opt->noOidn, "leave the peer out");
    CheckRange(real->add_option("--oidn-runs", opt->oidnRuns, "peer runs to time (median)")
                   ->capture_default_str(),
               1, 100, true);
    real->add_option("-o,--out", opt->out, "output directory")->capture_default_str();
    opt->device.Add(real);
    opt->methodOptions.Add(real);
    real->callback([opt] { RunBenchReal(*opt); });
}

}  // namespace mcd::tool
