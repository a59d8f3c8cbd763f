#include "host/api/png_sink.h"

#include <atomic>

#include "mcdenoise/error.h"

namespace mcd::api {

namespace {
std::atomic<PngWriter> installed{nullptr};
}  // namespace

void SetPngWriter(PngWriter writer) {
    installed.store(writer);
}

void WritePngThroughIo(const std::string &path, const Image &image) {
    PngWriter writer = installed.load();
    if (!writer)
        throw Error("cannot write '" + path +
                        "': writing a PNG needs the I/O library (libmcdenoise_io) linked",
                    ErrorKind::Io);
    writer(path, image, 1.f);
}

}  // namespace mcd::api
