// Denoise a frame file with the mcdenoise libraries:
//     denoise_frame IN.exr OUT.exr [METHOD [NAME=VALUE...]]
// METHOD is auto (the default), awr, bayes, pivot or rhf; NAME=VALUE sets a parameter of it
// (e.g. kappa=0.6). Prints the plan, the time and where the output went; the frame's
// alpha, if it has one, is written beside the result.
#include <mcdenoise/io.h>
#include <mcdenoise/mcdenoise.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

int main(int argc, char **argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s IN.exr OUT.exr [METHOD [NAME=VALUE...]]\n", argv[0]);
        return 2;
    }
    try {
        mcd::Method method(argc > 3 ? argv[3] : "auto");
        for (int i = 4; i < argc; ++i) {
            std::string setting = argv[i];
            size_t eq = setting.find('=');
            if (eq == std::string::npos)
                throw mcd::Error("expected NAME=VALUE, not " + setting,
                                 mcd::ErrorKind::InvalidArgument);
            method.SetText(setting.substr(0, eq), setting.substr(eq + 1));
        }
        mcd::Frame frame = mcd::ReadFrame(argv[1]);
        mcd::Device device;
        mcd::Result result = method.Run(device, frame);
        for (const std::string &line : result.plan) std::printf("  %s\n", line.c_str());
        for (const std::string &line : result.warnings)
            std::fprintf(stderr, "warning: %s\n", line.c_str());
        std::vector<std::pair<std::string, const mcd::Image *>> layers = {
            {"color", &result.image}};
        if (!result.alpha.Empty()) layers.push_back({"alpha", &result.alpha});
        mcd::WriteExr(argv[2], layers, {{"mcd:method", result.method}});
        std::printf("%s: %s on %s, %dx%d, %.1f ms (%.1f ms GPU), library %s\n", argv[2],
                    result.method.c_str(), device.Name().c_str(), result.image.width,
                    result.image.height, result.wallMs, result.GpuMs(), mcd::Version());
    } catch (const mcd::Error &e) {
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    }
    return 0;
}
