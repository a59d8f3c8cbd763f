// `mcdenoise bench real`: the figures beyond CompareImages' and the report (CSV, Markdown,
// HTML with a strip per scene and frame).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "host/error.h"
#include "tools/mcdenoise/bench_real.h"

namespace mcd::tool {
namespace {

namespace fs = std::filesystem;

const char *kFloorMark = "†";

}  // namespace

void MeasureRow(const Image &output, const Image &reference, const ObjectMap &objects,
                RealRow *row) {
    row->lights = MeasureObjectLights(output, reference, objects);

    // Each pixel's relMSE term over its first three channels; a non-finite output is the
    // worst a pixel can be.
    int channels = std::min({output.channels, reference.channels, 3});
    std::vector<double> terms(output.PixelCount());
    for (int y = 0; y < output.height; ++y)
        for (int x = 0; x < output.width; ++x) {
            double sum = 0;
            for (int c = 0; c < channels; ++c) {
                double v = output.At(c, y, x), r = reference.At(c, y, x);
                sum += std::isfinite(v) ? (v - r) * (v - r) / (r * r + 0.01) : INFINITY;
            }
            terms[size_t(y) * output.width + x] = sum / channels;
        }
    size_t count = std::max<size_t>(1, (terms.size() + 99) / 100);
    std::partial_sort(terms.begin(), terms.begin() + count, terms.end(), std::greater<>());
    double sum = 0;
    for (size_t i = 0; i < count; ++i) sum += terms[i];
    row->worst = sum / double(count);
}

Image MakeStrip(const std::vector<Image> &images, int gap) {
    int width = 0, height = 0;
    for (const Image &image : images) {
        width += image.width + (width ? gap : 0);
        height = std::max(height, image.height);
    }
    Image strip(width, height, 3);
    int left = 0;
    for (const Image &image : images) {
        for (int c = 0; c < 3; ++c)
            for (int y = 0; y < image.height; ++y)
                for (int x = 0; x < image.width; ++x)
                    strip.At(c, y, left + x) = image.At(std::min(c, image.channels - 1), y, x);
        left += image.width + gap;
    }
    return strip;
}

namespace {

// Per method and frame kind over the scenes where it ran: geometric means of relMSE, the
// brightness ratio, the worst 1% and the time; arithmetic means of PSNR and SSIM.
struct Summary {
    std::string frame, method;
    int ran = 0, scenes = 0;
    double relMse = 0, brightness = 0, worst = 0, psnr = 0, ssim = 0, seconds = 0;
    int timed = 0;
    // The darkest object over the scenes, "" where no scene has ids.
    std::string darkest;
};

// An object's light as the tables give it; NaN (a non-finite output) as "nan".
std::string Light(double ratio) {
    return fmt::format("{:.3f}", ratio);
}

// The row's darkest object: "0.799 (object 5)", or "" where none was measured.
std::string Darkest(const RealRow &row) {
    if (row.lights.darkestId < 0) return "";
    return fmt::format("{} (object {})", Light(row.lights.Darkest()), row.lights.darkestId);
}

std::vector<std::string> Ordered(const std::vector<RealRow> &rows, bool frames) {
    std::vector<std::string> names;
    for (const RealRow &row : rows) {
        const std::string &name = frames ? row.frame : row.method;
        if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
    return names;
}

std::vector<Summary> Summarize(const std::vector<RealRow> &rows) {
    std::vector<Summary> summaries;
    for (const std::string &frame : Ordered(rows, true))
        for (const std::string &method : Ordered(rows, false)) {
            Summary s{frame, method};
            double darkest = INFINITY;
            for (const RealRow &row : rows) {
                if (row.frame != frame || row.method != method) continue;
                ++s.scenes;
                if (!row.Ran()) continue;
                ++s.ran;
                s.relMse += std::log(row.error.relMse);
                s.brightness += std::log(row.error.brightness);
                s.worst += std::log(row.worst);
                s.psnr += row.error.psnr;
                s.ssim += row.error.ssim;
                if (row.seconds > 0) s.seconds += std::log(row.seconds), ++s.timed;
                if (row.lights.darkestId >= 0) {
                    double ratio = row.lights.Darkest();
                    double rank = std::isnan(ratio) ? -INFINITY : ratio;
                    if (rank < darkest) {
                        darkest = rank;
                        s.darkest = fmt::format("{} ({} object {})", Light(ratio), row.scene,
                                                row.lights.darkestId);
                    }
                }
            }
            if (!s.scenes) continue;
            if (s.ran) {
                s.relMse = std::exp(s.relMse / s.ran),
                s.brightness = std::exp(s.brightness / s.ran);
                s.worst = std::exp(s.worst / s.ran);
                s.psnr /= s.ran, s.ssim /= s.ran;
            }
            s.seconds = s.timed ? std::exp(s.seconds / s.timed) : -1;
            summaries.push_back(s);
        }
    return summaries;
}

std::string CsvField(const std::string &text) {
    if (text.find_first_of(",\"\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text)
        quoted += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
    return quoted + "\"";
}

std::string Escape(const std::string &text, bool html) {
    std::string out;
    for (char c : text) {
        if (html && c == '<')
            out += "&lt;";
        else if (html && c == '>')
            out += "&gt;";
        else if (html && c == '&')
            out += "&amp;";
        else if (!html && c == '|')
            out += "\\|";
        else
            out += c == '\n' ? ' ' : c;
    }
    return out;
}

std::string Shortened(const std::string &text, size_t length) {
    return text.size() <= length ? text : text.substr(0, length) + "...";
}

std::string Seconds(double seconds) {
    return seconds >= 0 ? fmt::format("{:.3f}", seconds) : "";
}

const RealScene *FindScene(const std::vector<RealScene> &scenes, const std::string &name) {
    for (const RealScene &scene : scenes)
        if (scene.name == name) return &scene;
    return nullptr;
}

// relMSE, marked where it is within 3x of the reference's own noise.
std::string RelMse(const RealRow &row, const std::vector<RealScene> &scenes) {
    const RealScene *scene = FindScene(scenes, row.scene);
    bool floor =
        scene && scene->referenceNoise > 0 && row.error.relMse < 3 * scene->referenceNoise;
    return fmt::format("{:.4g}{}", row.error.relMse, floor ? kFloorMark : "");
}

std::string Csv(const std::vector<RealRow> &rows) {
    std::string csv =
        "scene,frame,method,relmse,psnr,ssim,brightness,worst1pct,darkest_object,"
        "darkest_object_id,seconds,refused,note\n";
    for (const RealRow &r : rows) {
        std::string darkest = DarkestCsv(r.lights);
        csv += r.Ran() ? fmt::format("{},{},{},{:.6g},{:.4f},{:.5f},{:.5f},{:.6g},{},{},,{}\n",
                                     r.scene, r.frame, r.method, r.error.relMse, r.error.psnr,
                                     r.error.ssim, r.error.brightness, r.worst, darkest,
                                     Seconds(r.seconds), CsvField(r.note))
                       : fmt::format("{},{},{},,,,,,,,,{},\n", r.scene, r.frame,
                                     CsvField(r.method), CsvField(r.refused));
    }
    return csv;
}

// Per scene: the reference's spp and noise, and the inputs' relMSE it is to be far below.
std::string ReferenceTable(const std::vector<RealScene> &scenes,
                           const std::vector<RealRow> &rows) {
    std::string md =
        "| scene | reference spp | reference noise (relMSE) | plain input relMSE | "
        "accumulated input relMSE | smallest relMSE measured |\n|---|---|---|---|---|---|\n";
    for (const RealScene &scene : scenes) {
        std::map<std::string, double> input;
        double smallest = INFINITY;
        for (const RealRow &row : rows) {
            if (row.scene != scene.name || !row.Ran()) continue;
            if (row.method == "input") input[row.frame] = row.error.relMse;
            smallest = std::min(smallest, row.error.relMse);
        }
        auto figure = [](double v) {
            return std::isfinite(v) ? fmt::format("{:.4g}", v) : "-";
        };
        md += fmt::format(
            "| {} | {} | {} | {} | {} | {} |\n", scene.name, scene.referenceSpp,
            scene.referenceNoise >= 0 ? fmt::format("{:.3g}", scene.referenceNoise)
                                      : "no halves",
            figure(input.count("plain") ? input["plain"] : NAN),
            figure(input.count("accumulated") ? input["accumulated"] : NAN), figure(smallest));
    }
    return md;
}

// Per frame kind: a scene a row with its reference's own noise, a method a column,
// "relMSE / PSNR / SSIM (brightness)"; the geometric means (PSNR, SSIM: arithmetic) at
// the bottom.
std::string Matrix(const std::vector<RealScene> &scenes, const std::vector<RealRow> &rows,
                   const std::vector<Summary> &summaries, const std::string &frame) {
    std::vector<std::string> methods = Ordered(rows, false);
    std::string md = fmt::format("| {} | reference noise |", frame);
    for (const std::string &m : methods) md += " " + m + " |";
    md += "\n|---|---|";
    for (size_t i = 0; i < methods.size(); ++i) md += "---|";
    md += "\n";
    for (const RealScene &scene : scenes) {
        md +=
            fmt::format("| {} | {} |", scene.name,
                        scene.referenceNoise >= 0 ? fmt::format("{:.2g}", scene.referenceNoise)
                                                  : "unknown");
        for (const std::string &m : methods) {
            std::string cell = " ";
            for (const RealRow &row : rows)
                if (row.scene == scene.name && row.frame == frame && row.method == m)
                    cell = row.Ran() ? fmt::format("{} / {:.2f} / {:.3f} ({:.3f})",
                                                   RelMse(row, scenes), row.error.psnr,
                                                   row.error.ssim, row.error.brightness)
                                     : "refused";
            md += " " + cell + " |";
        }
        md += "\n";
    }
    md += "| mean over the scenes | |";
    for (const std::string &m : methods) {
        std::string cell = " ";
        for (const Summary &s : summaries)
            if (s.frame == frame && s.method == m && s.ran)
                cell = fmt::format(
                    "{:.4g} / {:.2f} / {:.3f} ({:.3f}){}", s.relMse, s.psnr, s.ssim,
                    s.brightness,
                    s.ran < s.scenes ? fmt::format(", {} of {}", s.ran, s.scenes) : "");
        md += " " + cell + " |";
    }
    return md + "\n";
}

std::string SummaryTable(const std::vector<Summary> &summaries) {
    std::string md =
        "| frame | method | scenes | relMSE | PSNR | SSIM | mean brightness | worst 1% | "
        "darkest object | time s |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Summary &s : summaries)
        md += s.ran ? fmt::format(
                          "| {} | {} | {} of {} | {:.4g} | {:.2f} | {:.4f} | {:.3f} | "
                          "{:.4g} | {} | {} |\n",
                          s.frame, s.method, s.ran, s.scenes, s.relMse, s.psnr, s.ssim,
                          s.brightness, s.worst, s.darkest, Seconds(s.seconds))
                    : fmt::format("| {} | {} | 0 of {} | refused | | | | | | |\n", s.frame,
                                  s.method, s.scenes);
    return md;
}

std::string RowTable(const std::vector<RealScene> &scenes, const std::vector<RealRow> &rows) {
    std::string md =
        "| scene | frame | method | relMSE | PSNR | SSIM | mean brightness | worst 1% | "
        "darkest object | time s | note |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const RealRow &r : rows)
        md += r.Ran() ? fmt::format(
                            "| {} | {} | {} | {} | {:.2f} | {:.4f} | {:.3f} | {:.4g} | "
                            "{} | {} | {} |\n",
                            r.scene, r.frame, r.method, RelMse(r, scenes), r.error.psnr,
                            r.error.ssim, r.error.brightness, r.worst, Darkest(r),
                            Seconds(r.seconds), Escape(Shortened(r.note, 200), false))
                      : fmt::format("| {} | {} | {} | refused | | | | | | | {} |\n", r.scene,
                                    r.frame, r.method, Escape(r.refused, false));
    return md;
}

// Per scene with object ids and frame: an object (id, pixels) a row, a method a column,
// the object's light over the reference's; "" where no scene has ids.
std::string ObjectTables(const std::vector<RealScene> &scenes,
                         const std::vector<RealRow> &rows) {
    std::vector<std::string> methods = Ordered(rows, false);
    std::string md;
    for (const RealScene &scene : scenes)
        for (const std::string &frame : Ordered(rows, true)) {
            std::map<int, int> pixels;
            for (const RealRow &row : rows)
                if (row.scene == scene.name && row.frame == frame)
                    for (const auto &[id, light] : row.lights.objects)
                        pixels[id] = light.pixels;
            if (pixels.empty()) continue;
            md += fmt::format("\n| {} {} | pixels |", scene.name, frame);
            for (const std::string &m : methods) md += " " + m + " |";
            md += "\n|---|---|";
            for (size_t i = 0; i < methods.size(); ++i) md += "---|";
            md += "\n";
            for (const auto &[id, count] : pixels) {
                md += fmt::format("| object {} | {} |", id, count);
                for (const std::string &m : methods) {
                    std::string cell = " ";
                    for (const RealRow &row : rows)
                        if (row.scene == scene.name && row.frame == frame && row.method == m &&
                            row.lights.objects.count(id))
                            cell = Light(row.lights.objects.at(id).ratio);
                    md += " " + cell + " |";
                }
                md += "\n";
            }
        }
    return md;
}

std::string Markdown(const std::string &header, const std::vector<RealScene> &scenes,
                     const std::vector<RealRow> &rows, const std::vector<Summary> &summaries) {
    std::string md = fmt::format(
        "# mcdenoise bench real\n\n{}\n\nrelMSE = mean((x - r)^2 / (r^2 + 0.01)); mean "
        "brightness = mean luminance of the output over the reference's; worst 1% = the mean "
        "relMSE term of the worst 1% of pixels; darkest object = the lowest light of an object "
        "over the reference's (below); time = denoise wall time (the methods: one "
        "run after an untimed warm-up, uploads and downloads included; the peer: its filter's "
        "own time, median over runs). {} marks a relMSE within 3x of the reference's own "
        "noise. Means over the scenes: geometric for relMSE, brightness, worst 1% and time, "
        "arithmetic for PSNR and SSIM.\n\n## References\n\n{}",
        header, kFloorMark, ReferenceTable(scenes, rows));
    for (const std::string &frame : Ordered(rows, true))
        md += fmt::format("\n## {} frames: relMSE / PSNR dB / SSIM (mean brightness)\n\n{}",
                          frame, Matrix(scenes, rows, summaries, frame));
    md += "\n## Means over the scenes\n\n" + SummaryTable(summaries);
    if (std::string objects = ObjectTables(scenes, rows); !objects.empty())
        md += fmt::format(
            "\n## Objects: light over the reference's\n\nRec. 709 luminance summed over "
            "the pixels of an object id (the frames' objectId layer; objects of {} pixels or "
            "more; not an id most of whose pixels are empty, alpha 0: a transparent film's "
            "background) in the output, over the reference's.\n{}",
            kObjectPixels, objects);
    md += "\n## Every row\n\n" + RowTable(scenes, rows);
    return md;
}

// The Markdown tables above as HTML tables (cells split at unescaped '|').
std::string HtmlTables(const std::string &md) {
    std::string html, line;
    bool inTable = false, head = true;
    std::istringstream stream(md);
    while (std::getline(stream, line)) {
        if (line.rfind("|", 0) != 0) {
            if (inTable) html += "</table>\n";
            inTable = false;
            if (line.rfind("## ", 0) == 0)
                html += "<h3>" + Escape(line.substr(3), true) + "</h3>\n";
            continue;
        }
        if (line.rfind("|---", 0) == 0) continue;
        if (!inTable) html += "<table>\n", inTable = true, head = true;
        std::vector<std::string> cells;
        std::string cell;
        for (size_t i = 1; i < line.size(); ++i) {
            if (line[i] == '\\' && i + 1 < line.size() && line[i + 1] == '|')
                cell += line[++i];
            else if (line[i] == '|')
                cells.push_back(cell), cell.clear();
            else
                cell += line[i];
        }
        html += "<tr>";
        for (const std::string &c : cells)
            html += fmt::format("<{0}>{1}</{0}>", head ? "th" : "td", Escape(c, true));
        html += "</tr>\n";
        head = false;
    }
    return html + (inTable ? "</table>\n" : "");
}

// Per scene and frame: the previews side by side with their figures, then the refusals.
std::string HtmlStrips(const std::vector<RealScene> &scenes, const std::vector<RealRow> &rows) {
    std::string html;
    for (const RealScene &scene : scenes) {
        html += fmt::format(
            "<h2 id='{0}'>{0}</h2><p>reference: {1} spp, its own relMSE noise "
            "{2}</p>\n",
            scene.name, scene.referenceSpp,
            scene.referenceNoise >= 0 ? fmt::format("{:.3g}", scene.referenceNoise)
                                      : "unknown (no halves)");
        for (const std::string &frame : Ordered(rows, true)) {
            std::string strip, refused;
            for (const RealRow &r : rows) {
                if (r.scene != scene.name || r.frame != frame) continue;
                if (!r.Ran()) {
                    refused +=
                        fmt::format("<li>{}: {}</li>", r.method, Escape(r.refused, true));
                    continue;
                }
                strip += fmt::format(
                    "<figure><img src='{}'><figcaption><b>{}</b><br>relMSE {} &middot; "
                    "mean {:.3f}<br>SSIM {:.3f}{}</figcaption></figure>",
                    r.png, r.method, RelMse(r, scenes), r.error.brightness, r.error.ssim,
                    r.seconds >= 0 ? fmt::format(" &middot; {:.2f} s", r.seconds) : "");
            }
            strip += fmt::format(
                "<figure><img src='{}'><figcaption><b>reference</b><br>{} "
                "spp</figcaption></figure>",
                scene.referencePng, scene.referenceSpp);
            html += fmt::format("<h3>{} frame</h3><div class='strip'>{}</div>\n", frame, strip);
            if (!refused.empty()) html += "<p>Refused:</p><ul>" + refused + "</ul>\n";
        }
    }
    return html;
}

}  // namespace

void WriteRealReport(const std::string &out, const std::string &header,
                     const std::vector<RealScene> &scenes, const std::vector<RealRow> &rows) {
    std::vector<Summary> summaries = Summarize(rows);
    std::string md = Markdown(header, scenes, rows, summaries);
    std::string html = fmt::format(
        "<!doctype html><html><head><meta charset='utf-8'><title>mcdenoise bench real</title>"
        "<style>body{{font-family:sans-serif}} td,th{{padding:2px 8px;text-align:right}} "
        ".strip{{display:flex;gap:4px;overflow-x:auto}} figure{{margin:0;font-size:12px}} "
        "figure img{{width:256px;image-rendering:pixelated}}</style></head><body>"
        "<h1>mcdenoise bench real</h1><p>{}</p>\n{}\n{}</body></html>\n",
        Escape(header, true), HtmlStrips(scenes, rows),
        HtmlTables(md.substr(md.find("## References"))));
    fs::path dir(out);
    std::ofstream(dir / "real.csv") << Csv(rows);
    std::ofstream(dir / "real.md") << md;
    std::ofstream(dir / "index.html") << html;
    fmt::print("\n## References\n\n{}", ReferenceTable(scenes, rows));
    for (const std::string &frame : Ordered(rows, true))
        fmt::print("\n## {} frames: relMSE / PSNR dB / SSIM (mean brightness)\n\n{}", frame,
                   Matrix(scenes, rows, summaries, frame));
    fmt::print("\n## Means over the scenes\n\n{}", SummaryTable(summaries));
    fmt::print("\nwrote {0}/real.csv, {0}/real.md, {0}/index.html and the strips\n", out);
}

}  // namespace mcd::tool
