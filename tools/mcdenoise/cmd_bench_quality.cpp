// `mcdenoise bench quality`: error against run time. For each scene and a ladder of sample
// counts: render (timed), run every method the frame supports (timed, wall and GPU),
// measure each against the cached reference; write a CSV, a log-log SVG plot per scene,
// crops, and an HTML report that opens from disk; print the headline figures.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "host/error.h"
#include "host/metrics.h"
#include "tools/mcdenoise/commands.h"
#include "tools/mcdenoise/method_options.h"
#include "tools/mcdenoise/object_light.h"
#include "tools/mcdenoise/path_guard.h"
#include "tools/mcdenoise/reference_cache.h"
#include "tools/mcdenoise/usage.h"
#include "tools/render/renderer.h"

namespace mcd::tool {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double Seconds(Clock::duration d) {
    return std::chrono::duration<double>(d).count();
}

struct QualityOptions {
    std::string scenes = "all", spp = "1,2,4,8,16,32,64", size = "128x128", methods = "all",
                out = "out/bench-quality";
    int referenceSpp = 2048, cropSpp = 8, threads = 0;
    DeviceOptions device;
    MethodOptions methodOptions;
};

// One measured point: `method` is "mc" for the plain render.
struct Point {
    std::string scene, method;
    int spp = 0;
    double renderSeconds = 0, denoiseSeconds = 0, gpuSeconds = 0;
    ErrorMetrics error;
    ObjectLights lights;  // each object's light, where the frame has ids
    double Total() const { return renderSeconds + denoiseSeconds; }
};

// The point's figures, and its darkest object by the frame's ids where it has them.
void Measure(Point &p, const Image &output, const Image &reference, const io::Frame &frame) {
    p.error = CompareImages(output, reference);
    if (frame.Has("objectId"))
        p.lights = MeasureObjectLights(output, reference, ObjectsOf(frame));
}

// The four figures no table shows apart: relMSE / PSNR / SSIM (mean brightness).
std::string Figures(const ErrorMetrics &e) {
    return fmt::format("{:.4g} / {:.2f} / {:.3f} ({:.3f})", e.relMse, e.psnr, e.ssim,
                       e.brightness);
}

// The figures as a line gives them, with the darkest object where one was measured.
std::string LineFigures(const Point &p) {
    return Figures(p.error) + (p.lights.darkestId >= 0
                                   ? fmt::format(", darkest object {:.3f} ({})",
                                                 p.lights.Darkest(), p.lights.darkestId)
                                   : "");
}

std::vector<std::string> SplitList(const std::string &text) {
    std::vector<std::string> items;
    std::stringstream stream(text);
    for (std::string item; std::getline(stream, item, ',');)
        if (!item.empty()) items.push_back(item);
    return items;
}

bool Listed(const std::vector<std::string> &list, const std::string &name) {
    return std::find(list.begin(), list.end(), name) != list.end();
}

// Time a curve needs to reach `error`, by log-log interpolation between its points
// (sorted by spp). Negative when the curve never gets that low; `*atFirst` when its first
// point is already below (the time is then an upper bound).
double TimeToReach(const std::vector<Point> &curve, double error, bool *atFirst) {
    *atFirst = false;
    if (curve.empty()) return -1;
    if (curve[0].error.relMse <= error) {
        *atFirst = true;
        return curve[0].Total();
    }
    for (size_t i = 0; i + 1 < curve.size(); ++i) {
        double e0 = curve[i].error.relMse, e1 = curve[i + 1].error.relMse;
        if (e0 >= error && e1 <= error && e0 > 0 && e1 > 0 && e0 != e1) {
            double t = (std::log(error) - std::log(e0)) / (std::log(e1) - std::log(e0));
            return std::exp(std::log(curve[i].Total()) +
                            t * (std::log(curve[i + 1].Total()) - std::log(curve[i].Total())));
        }
    }
    return -1;
}

// Error of a curve at `seconds` by log-log interpolation; clamped to its ends (`*clamped`).
double ErrorAt(const std::vector<Point> &curve, double seconds, bool *clamped) {
    *clamped = false;
    for (size_t i = 0; i + 1 < curve.size(); ++i) {
        double t0 = curve[i].Total(), t1 = curve[i + 1].Total();
        if (t0 <= seconds && seconds <= t1 && t0 > 0 && t1 > t0) {
            double t = (std::log(seconds) - std::log(t0)) / (std::log(t1) - std::log(t0));
            return std::exp(
                std::log(curve[i].error.relMse) +
                t * (std::log(curve[i + 1].error.relMse) - std::log(curve[i].error.relMse)));
        }
    }
    *clamped = true;
    return seconds < curve.front().Total() ? curve.front().error.relMse
                                           : curve.back().error.relMse;
}

// A log-log plot of relMSE against total time, one polyline per method, as SVG.
std::string PlotSvg(const std::string &scene,
                    const std::vector<std::pair<std::string, std::vector<Point>>> &curves) {
    double tMin = INFINITY, tMax = 0, eMin = INFINITY, eMax = 0;
    for (const auto &[name, curve] : curves)
        for (const Point &p : curve) {
            if (!(p.Total() > 0) || !(p.error.relMse > 0) || !std::isfinite(p.error.relMse))
                continue;
            tMin = std::min(tMin, p.Total()), tMax = std::max(tMax, p.Total());
            eMin = std::min(eMin, p.error.relMse), eMax = std::max(eMax, p.error.relMse);
        }
    if (!(tMax > 0) || !(eMax > 0)) return "";
    double x0 = std::floor(std::log10(tMin)), x1 = std::ceil(std::log10(tMax));
    double y0 = std::floor(std::log10(eMin)), y1 = std::ceil(std::log10(eMax));
    x1 = std::max(x1, x0 + 1), y1 = std::max(y1, y0 + 1);
    const int w = 640, h = 420, left = 70, right = 150, top = 30, bottom = 50;
    auto px = [&](double t) {
        return left + (std::log10(t) - x0) / (x1 - x0) * (w - left - right);
    };
    auto py = [&](double e) {
        return top + (y1 - std::log10(e)) / (y1 - y0) * (h - top - bottom);
    };
    std::string svg = fmt::format(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{}' height='{}' "
        "font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
        "fill='white'/>\n<text x='{}' y='18' font-size='14'>{}: relMSE against render + "
        "denoise time</text>\n",
        w, h, left, scene);
    for (double d = x0; d <= x1; ++d)
        svg += fmt::format(
            "<line x1='{0:.1f}' y1='{1}' x2='{0:.1f}' y2='{2}' stroke='#ddd'/><text "
            "x='{0:.1f}' "
            "y='{3}' text-anchor='middle'>1e{4:g} s</text>\n",
            px(std::pow(10, d)), top, h - bottom, h - bottom + 16, d);
    for (double d = y0; d <= y1; ++d)
        svg += fmt::format(
            "<line x1='{0}' y1='{1:.1f}' x2='{2}' y2='{1:.1f}' stroke='#ddd'/><text x='{3}' "
            "y='{1:.1f}' text-anchor='end' dy='4'>1e{4:g}</text>\n",
            left, py(std::pow(10, d)), w - right, left - 6, d);
    const char *colors[] = {"#000000", "#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e"};
    int index = 0;
    for (const auto &[name, curve] : curves) {
        const char *color = colors[index % 6];
        std::string points;
        for (const Point &p : curve)
            if (p.Total() > 0 && p.error.relMse > 0 && std::isfinite(p.error.relMse)) {
                points += fmt::format("{:.1f},{:.1f} ", px(p.Total()), py(p.error.relMse));
                svg += fmt::format(
                    "<circle cx='{:.1f}' cy='{:.1f}' r='3' fill='{}'><title>{} {} spp: "
                    "{:.4g} s, relMSE {:.4g}</title></circle>\n",
                    px(p.Total()), py(p.error.relMse), color, name, p.spp, p.Total(),
                    p.error.relMse);
            }
        svg +=
            fmt::format("<polyline points='{}' fill='none' stroke='{}' stroke-width='{}'/>\n",
                        points, color, name == "mc" ? 2.5 : 1.5);
        svg += fmt::format("<text x='{}' y='{}' fill='{}'>{}</text>\n", w - right + 10,
                           top + 16 * (index + 1), color, name == "mc" ? "Monte Carlo" : name);
        ++index;
    }
    return svg + "</svg>\n";
}

// What a run measures: the size, the scenes, the ladder of sample counts and the methods.
struct QualityPlan {
    int width = 0, height = 0;
    std::vector<std::string> scenes;
    std::vector<int> ladder;  // sorted, without repeats
    std::vector<Method> methods;
};

// The plan from the options, every name and count refused before any work.
QualityPlan PlanQuality(const QualityOptions &opt) {
    QualityPlan plan;
    ParseSize(opt.size, &plan.width, &plan.height);
    plan.scenes = opt.scenes == "all" ? render::SceneNames() : SplitList(opt.scenes);
    for (const std::string &s : plan.scenes) render::BuildScene(s);  // unknown names fail here
    for (const std::string &s : SplitList(opt.spp)) {
        int n = 0;
        try {
            n = std::stoi(s);
        } catch (...) {
        }
        if (n < 1 || n >= opt.referenceSpp)
            throw Error(fmt::format("--spp: '{}' is not a sample count in 1..{}", s,
                                    opt.referenceSpp - 1),
                        ErrorKind::InvalidArgument);
        plan.ladder.push_back(n);
    }
    std::sort(plan.ladder.begin(), plan.ladder.end());
    plan.ladder.erase(std::unique(plan.ladder.begin(), plan.ladder.end()), plan.ladder.end());
    if (plan.ladder.empty()) throw Error("--spp: no sample counts", ErrorKind::InvalidArgument);
    std::vector<std::string> names = MethodNames();
    names.push_back("auto");
    for (const std::string &name : names)
        if (opt.methods == "all" || Listed(SplitList(opt.methods), name))
            plan.methods.push_back(opt.methodOptions.Make(name));
    if (opt.methods != "all")
        for (const std::string &name : SplitList(opt.methods))
            if (std::none_of(plan.methods.begin(), plan.methods.end(),
                             [&](const Method &m) { return m.Name() == name; }))
                throw Error(fmt::format("--methods: unknown method '{}' (methods: {})", name,
                                        MethodOptions::Names()),
                            ErrorKind::InvalidArgument);
    return plan;
}

// The report's files must spare the cached references it reads; then its directory is made.
void PrepareReport(const QualityOptions &opt, const QualityPlan &plan) {
    std::vector<RolePath> references,
        reports = {{"-o", (fs::path(opt.out) / "quality.csv").string()},
                   {"-o", (fs::path(opt.out) / "index.html").string()}};
    for (const std::string &scene : plan.scenes) {
        references.push_back(
            {"the cached reference",
             ReferenceCachePath(scene, plan.width, plan.height, opt.referenceSpp)});
        reports.push_back({"-o", (fs::path(opt.out) / (scene + ".svg")).string()});
        std::vector<std::string> crops = {"input", "reference"};
        for (const Method &m : plan.methods) crops.push_back(m.Name());
        for (const std::string &crop : crops)
            reports.push_back(
                {"-o", (fs::path(opt.out) / fmt::format("{}-{}.png", scene, crop)).string()});
    }
    RefuseOverwritingInputs(references, reports);
    PrepareDirectory(opt.out);
}

// One scene's measurements: a curve per method ("mc" first), the methods left out and
// why, the crops at --crop-spp.
struct SceneCurves {
    std::vector<std::pair<std::string, std::vector<Point>>> curves;
    std::map<std::string, std::string> skipped;
    std::map<std::string, Image> crops;
};

// A rendered frame's layers as a frame (moved out of `r`).
io::Frame FrameOf(render::RenderResult &r, const std::string &scene, int spp, int width,
                  int height) {
    io::Frame frame;
    frame.path = fmt::format("{} at {} spp", scene, spp);
    frame.width = width, frame.height = height;
    for (auto &[name, image] : r.layers) frame.layers[name] = std::move(image);
    return frame;
}

// The renders of one rung of the ladder: the plain frame (color, variance, spp, min, max)
// and the one with every layer group, with their times.
struct Rung {
    int spp = 0;
    io::Frame plain, full;
    double plainSeconds = 0, fullSeconds = 0;
};

// Method m on the rung: the plain frame when it holds every layer the method reads, and its
// render time; else the frame with every layer group (bayes splits direct and indirect when
// a frame has them: relief-abc 4 spp 11.4 without the split, 0.10 with it). auto takes
// every layer group (its candidates need them), and its time is that of every candidate it
// ran. Returns the line's part for it.
std::string MeasureMethod(const QualityOptions &opt, Device &device, const Method &method,
                          const Rung &rung, const Image &reference, const std::string &scene,
                          std::set<std::string> &warm, SceneCurves &s, size_t m) {
    bool needsMore = method.Name() == "auto" || !method.Missing(rung.plain).empty();
    for (const std::string &layer : method.Uses())
        needsMore |= !rung.plain.Has(layer) && rung.full.Has(layer);
    const io::Frame &frame = needsMore ? rung.full : rung.plain;
    double renderSeconds = needsMore ? rung.fullSeconds : rung.plainSeconds;
    try {
        // Untimed until a run has dispatched (and so compiled) its kernels: a frame with
        // nothing to do (1 spp: no variance) dispatches nothing.
        if (!warm.count(method.Name()) && !method.Run(device, frame).timings.empty())
            warm.insert(method.Name());
        Clock::time_point start = Clock::now();
        Result result = method.Run(device, frame);
        Point p{scene, method.Name(), rung.spp, renderSeconds, Seconds(Clock::now() - start)};
        p.gpuSeconds = result.GpuMs() * 1e-3;
        Measure(p, result.image, reference, rung.full);
        s.curves[m + 1].second.push_back(p);
        if (rung.spp == opt.cropSpp) s.crops[method.Name()] = std::move(result.image);
        return fmt::format("\n    {:<6} {} in {:.2f} s", method.Name(), LineFigures(p),
                           p.Total());
    } catch (const Error &e) {
        // A frame that lacks a method's layers fails the same way at every spp.
        s.skipped[method.Name()] = e.what();
        return fmt::format("\n    {:<6} skipped", method.Name());
    }
}

// Every rung of the ladder for one scene: the render (timed) and each method on it.
SceneCurves MeasureScene(const QualityOptions &opt, const QualityPlan &plan, Device &device,
                         const std::string &sceneName, const Image &reference) {
    render::Scene scene = render::BuildScene(sceneName);
    SceneCurves s;
    s.curves = {{"mc", {}}};
    for (const Method &m : plan.methods) s.curves.push_back({m.Name(), {}});
    std::set<std::string> warm;
    for (int spp : plan.ladder) {
        render::RenderOptions options;
        options.width = plan.width, options.height = plan.height, options.spp = spp;
        options.threads = opt.threads;
        render::RenderResult plain = render::Render(scene, options);
        Image plainColor = plain.layers[0].second;
        // Every layer group, for the methods that need more than the plain frame has.
        options.layers = render::kLayersAll;
        render::RenderResult full = render::Render(scene, options);
        Rung rung{spp, FrameOf(plain, sceneName, spp, plan.width, plan.height),
                  FrameOf(full, sceneName, spp, plan.width, plan.height), plain.seconds,
                  full.seconds};
        Point mc{sceneName, "mc", spp, plain.seconds};
        Measure(mc, plainColor, reference, rung.full);
        s.curves[0].second.push_back(mc);
        if (spp == opt.cropSpp) s.crops["input"] = plainColor;
        std::string line = fmt::format(
            "  {} {} spp, relMSE / PSNR dB / SSIM (mean brightness):\n    {:<6} {} in "
            "{:.2f} s",
            sceneName, spp, "mc", LineFigures(mc), mc.renderSeconds);
        for (size_t m = 0; m < plan.methods.size(); ++m)
            if (!s.skipped.count(plan.methods[m].Name()))
                line += MeasureMethod(opt, device, plan.methods[m], rung, reference, sceneName,
                                      warm, s, m);
        fmt::print("{}\n", line);
        std::fflush(stdout);
    }
    return s;
}

// Headline: the speedup at the error MC reaches at the top of the ladder, and the error at
// the time MC takes to get there; markdown rows into `headline`, an HTML table returned.
std::string HeadlineTable(const std::string &sceneName, const SceneCurves &s,
                          std::string &headline) {
    const Point &top = s.curves[0].second.back();
    std::string table = fmt::format(
        "<table><tr><th>method</th><th>speedup at equal error</th><th>error at equal "
        "time (MC / method)</th><th>at {} spp: relMSE / PSNR / SSIM (mean "
        "brightness)</th></tr>\n<tr><td>mc</td><td></td><td></td><td>{}</td></tr>\n",
        top.spp, Figures(top.error));
    headline += fmt::format("| {} | mc | | | {} |\n", sceneName, Figures(top.error));
    for (size_t m = 1; m < s.curves.size(); ++m) {
        const std::vector<Point> &curve = s.curves[m].second;
        if (curve.empty()) continue;
        bool atFirst = false, clamped = false;
        double t = TimeToReach(curve, top.error.relMse, &atFirst);
        double e = ErrorAt(curve, top.Total(), &clamped);
        std::string speedup =
            t > 0 ? fmt::format("{}{:.2f}x", atFirst ? ">= " : "", top.Total() / t)
                  : "not reached";
        std::string ratio = fmt::format("{}{:.2f}x", clamped ? "~" : "", top.error.relMse / e);
        // The method's own figures at the top of the ladder, where it ran there.
        std::string own = curve.back().spp == top.spp ? Figures(curve.back().error) : "";
        headline += fmt::format("| {} | {} | {} | {} | {} |\n", sceneName, s.curves[m].first,
                                speedup, ratio, own);
        table += fmt::format("<tr><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
                             s.curves[m].first, speedup, ratio, own);
    }
    return table + "</table>\n";
}

// The centre half of the frame of each crop, side by side, written as PNGs; the HTML.
std::string CropsHtml(const QualityOptions &opt, const QualityPlan &plan,
                      const std::string &sceneName, SceneCurves &s, const Image &reference) {
    if (s.crops.empty()) return "";
    int x0 = plan.width / 4, y0 = plan.height / 4, x1 = std::max(x0 + 1, 3 * plan.width / 4),
        y1 = std::max(y0 + 1, 3 * plan.height / 4);
    s.crops["reference"] = reference;
    std::string html = fmt::format("<p>Crops at {} spp:</p><table><tr>", opt.cropSpp);
    std::vector<std::string> order = {"input"};
    for (const Method &m : plan.methods) order.push_back(m.Name());
    order.push_back("reference");
    for (const std::string &name : order) {
        if (!s.crops.count(name)) continue;
        std::string file = fmt::format("{}-{}.png", sceneName, name);
        io::WritePng((fs::path(opt.out) / file).string(), s.crops[name].Crop(x0, y0, x1, y1));
        html += fmt::format("<td><img class='crop' src='{}'><br>{}</td>", file, name);
    }
    return html + "</tr></table>\n";
}

// One scene's section of the report: the plot (written), the headline table, what was
// left out, the crops (written).
std::string SceneHtml(const QualityOptions &opt, const QualityPlan &plan,
                      const std::string &sceneName, SceneCurves &s, const Image &reference,
                      std::string &headline) {
    const Point &top = s.curves[0].second.back();
    std::string table = HeadlineTable(sceneName, s, headline);
    std::string svgName = sceneName + ".svg";
    std::ofstream(fs::path(opt.out) / svgName) << PlotSvg(sceneName, s.curves);
    std::string html = fmt::format(
        "<h2>{}</h2><img src='{}'>\n<p>Monte Carlo at {} spp: relMSE / PSNR / SSIM (mean "
        "brightness) {} in {:.3f} s.</p>{}",
        sceneName, svgName, top.spp, Figures(top.error), top.Total(), table);
    for (const auto &[name, why] : s.skipped)
        html += fmt::format("<p>{} left out: {}</p>\n", name, why);
    return html + CropsHtml(opt, plan, sceneName, s, reference);
}

std::string HtmlHeader(const QualityOptions &opt, const QualityPlan &plan, Device &device) {
    return fmt::format(
        "<!doctype html><html><head><meta charset='utf-8'><title>mcdenoise bench "
        "quality</title><style>body{{font-family:sans-serif}} td,th{{padding:2px 8px;"
        "text-align:right}} img.crop{{image-rendering:pixelated;width:192px}}"
        "</style></head><body><h1>Error against run time</h1><p>{}x{}, references at {} "
        "spp, device {}. Time is render + denoise (wall; the first run of each method is "
        "an untimed warm-up that compiles its pipelines). A method runs on the plain frame "
        "(color, variance, spp, min, max) when that is all it reads, else on a frame with "
        "every layer group, and is charged that frame's render time.</p>\n",
        plan.width, plan.height, opt.referenceSpp, device.Name());
}

void WriteCsv(const QualityOptions &opt, const std::vector<Point> &points) {
    std::string csv =
        "scene,spp,method,render_s,denoise_wall_s,denoise_gpu_s,total_s,relmse,psnr,ssim,"
        "brightness,darkest_object,darkest_object_id\n";
    for (const Point &p : points)
        csv +=
            fmt::format("{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4f},{:.5f},{:.5f},{}\n",
                        p.scene, p.spp, p.method, p.renderSeconds, p.denoiseSeconds,
                        p.gpuSeconds, p.Total(), p.error.relMse, p.error.psnr, p.error.ssim,
                        p.error.brightness, DarkestCsv(p.lights));
    std::ofstream(fs::path(opt.out) / "quality.csv") << csv;
}

void RunBenchQuality(const QualityOptions &opt) {
    QualityPlan plan = PlanQuality(opt);
    PrepareReport(opt, plan);
    Device device(opt.device.Options());
    fmt::print("bench quality: {} scene(s) at {}x{}, spp {}, methods {}, on {}\n",
               plan.scenes.size(), plan.width, plan.height, opt.spp,
               plan.methods.empty() ? "none" : opt.methods, device.Name());
    std::vector<Point> points;
    std::string html = HtmlHeader(opt, plan, device), headline;
    for (const std::string &sceneName : plan.scenes) {
        bool rendered = false;
        io::Frame referenceFrame = CachedReference(sceneName, plan.width, plan.height,
                                                   opt.referenceSpp, opt.threads, &rendered);
        const Image &reference = referenceFrame.Get("color");
        SceneCurves s = MeasureScene(opt, plan, device, sceneName, reference);
        for (auto &[name, curve] : s.curves)
            points.insert(points.end(), curve.begin(), curve.end());
        html += SceneHtml(opt, plan, sceneName, s, reference, headline);
    }
    WriteCsv(opt, points);
    std::ofstream(fs::path(opt.out) / "index.html") << html << "</body></html>\n";
    fmt::print(
        "\n| scene | method | speedup at equal error | error at equal time | at the top spp: "
        "relMSE / PSNR / SSIM (mean brightness) |\n|---|---|---|---|---|\n{}",
        headline);
    fmt::print("wrote {}/quality.csv, {}/index.html and a plot per scene\n", opt.out, opt.out);
}

}  // namespace

void AddBenchQualityCommand(CLI::App *bench) {
    auto opt = std::make_shared<QualityOptions>();
    CLI::App *quality = bench->add_subcommand(
        "quality",
        "Error against run time of every method over a ladder of spp per scene\n\n"
        "Renders each scene at a ladder of spp, runs every method, measures against cached "
        "references; writes a CSV (relMSE, PSNR, SSIM, mean brightness, the darkest object's "
        "light "
        "by the frame's objectId: docs/real-scenes.md), SVG plots and an HTML report.");
    quality->add_option("--scenes", opt->scenes, "comma-separated scene names, or all")
        ->capture_default_str();
    quality->add_option("--spp", opt->spp, "the ladder of sample counts")
        ->capture_default_str();
    quality->add_option("--size", opt->size, "image size WxH")->capture_default_str();
    quality->add_option("--methods", opt->methods, "comma-separated methods, or all")
        ->capture_default_str();
    CheckRange(
        quality->add_option("--reference-spp", opt->referenceSpp, "spp of the references")
            ->capture_default_str(),
        2, 1 << 20, true);
    quality->add_option("--crop-spp", opt->cropSpp, "spp of the crops in the report")
        ->capture_default_str();
    quality->add_option("--threads", opt->threads, "render threads (default: all cores)");
    quality->add_option("-o,--out", opt->out, "output directory")->capture_default_str();
    opt->device.Add(quality);
    opt->methodOptions.Add(quality);
    quality->callback([opt] { RunBenchQuality(*opt); });
}

}  // namespace mcd::tool
