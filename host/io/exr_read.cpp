#include "host/io/exr_read.h"

#include <Imath/ImathBox.h>
#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfCompression.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfThreading.h>
#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <exception>
#include <map>
#include <mutex>
#include <new>
#include <stdexcept>
#include <system_error>
#include <thread>

#ifdef MCD_HAVE_LIBDEFLATE
#include <libdeflate.h>
#else
#include <zlib.h>
#endif
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "host/error.h"
#include "host/io/image_file.h"

namespace mcd::io {

namespace {

// Inflates one zlib stream (a ZIP chunk) into a buffer of known size: libdeflate where the
// build has it (about five times zlib's speed on our frames), else zlib.
class Inflater {
  public:
    Inflater() {
#ifdef MCD_HAVE_LIBDEFLATE
        decompressor = libdeflate_alloc_decompressor();
        if (!decompressor) throw std::bad_alloc();
#endif
    }
    ~Inflater() {
#ifdef MCD_HAVE_LIBDEFLATE
        libdeflate_free_decompressor(decompressor);
#endif
    }
    Inflater(const Inflater &) = delete;
    Inflater &operator=(const Inflater &) = delete;

    // False when the stream is damaged, is not exactly the inSize bytes given (a chunk's
    // packed size that is too large is damage: OpenEXR's reader, which reads the next chunk
    // from where this one ended, fails on it, so ours must too, whatever the order in which
    // the threads fetch chunks) or does not inflate to exactly outSize bytes.
    bool Inflate(const char *in, size_t inSize, unsigned char *out, size_t outSize) {
#ifdef MCD_HAVE_LIBDEFLATE
        size_t used = 0, got = 0;
        return libdeflate_zlib_decompress_ex(decompressor, in, inSize, out, outSize, &used,
                                             &got) == LIBDEFLATE_SUCCESS &&
               used == inSize && got == outSize;
#else
        uLongf got = uLongf(outSize);
        uLong used = uLong(inSize);
        return uncompress2(out, &got, reinterpret_cast<const Bytef *>(in), &used) == Z_OK &&
               used == inSize && got == outSize;
#endif
    }

  private:
#ifdef MCD_HAVE_LIBDEFLATE
    libdeflate_decompressor *decompressor = nullptr;
#endif
};

// The sum of n bytes, modulo 256.
uint8_t ByteSum(const unsigned char *p, size_t n) {
    uint64_t sum = 0;
    size_t i = 0;
#ifdef __SSE2__
    __m128i acc = _mm_setzero_si128(), zero = _mm_setzero_si128();
    for (; i + 16 <= n; i += 16)
        acc = _mm_add_epi64(
            acc, _mm_sad_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i *>(p + i)), zero));
    sum = uint64_t(_mm_cvtsi128_si64(acc)) +
          uint64_t(_mm_cvtsi128_si64(_mm_unpackhi_epi64(acc, acc)));
#endif
    for (; i < n; ++i) sum += p[i];
    return uint8_t(sum);
}

// Restore t[i] = t[i-1] + d[i] - 128 over n bytes in place, t[-1] being `value`; returns
// the last t. Sixteen bytes at a time: a prefix sum within the block in four shifted adds.
uint8_t RestoreRun(unsigned char *d, size_t n, uint8_t value) {
    size_t i = 0;
#ifdef __SSE2__
    const __m128i bias = _mm_set1_epi8(char(-128));
    for (; i + 16 <= n; i += 16) {
        __m128i *block = reinterpret_cast<__m128i *>(d + i);
        __m128i x = _mm_sub_epi8(_mm_loadu_si128(block), bias);
        x = _mm_add_epi8(x, _mm_slli_si128(x, 1));
        x = _mm_add_epi8(x, _mm_slli_si128(x, 2));
        x = _mm_add_epi8(x, _mm_slli_si128(x, 4));
        x = _mm_add_epi8(x, _mm_slli_si128(x, 8));
        x = _mm_add_epi8(x, _mm_set1_epi8(char(value)));
        _mm_storeu_si128(block, x);
        value = uint8_t(_mm_extract_epi16(x, 7) >> 8);
    }
#endif
    for (; i < n; ++i) {
        value = uint8_t(value + d[i] - 128);
        d[i] = value;
    }
    return value;
}

// out[2k] = even[k], out[2k+1] = odd[k] for k < n.
void Interleave(const unsigned char *even, const unsigned char *odd, size_t n,
                unsigned char *out) {
    size_t k = 0;
#ifdef __SSE2__
    for (; k + 16 <= n; k += 16) {
        __m128i e = _mm_loadu_si128(reinterpret_cast<const __m128i *>(even + k));
        __m128i o = _mm_loadu_si128(reinterpret_cast<const __m128i *>(odd + k));
        _mm_storeu_si128(reinterpret_cast<__m128i *>(out + 2 * k), _mm_unpacklo_epi8(e, o));
        _mm_storeu_si128(reinterpret_cast<__m128i *>(out + 2 * k + 16),
                         _mm_unpackhi_epi8(e, o));
    }
#endif
    for (; k < n; ++k) {
        out[2 * k] = even[k];
        out[2 * k + 1] = odd[k];
    }
}

// One wanted channel within a scanline of a chunk: its bytes and where they go.
struct Piece {
    size_t offset = 0, bytes = 0;  // within the line
    Imf::PixelType type = Imf::FLOAT;
    float *plane = nullptr;
};

// Widen one row of a channel, as stored (little-endian), into floats.
void StoreRow(const unsigned char *bytes, Imf::PixelType type, int width, float *row) {
    if (type == Imf::FLOAT) {
        std::memcpy(row, bytes, size_t(width) * 4);
    } else if (type == Imf::HALF) {
        for (int x = 0; x < width; ++x) {
            uint16_t bits;
            std::memcpy(&bits, bytes + 2 * size_t(x), 2);
            Imath::half h;
            h.setBits(bits);
            row[x] = float(h);
        }
    } else {
        for (int x = 0; x < width; ++x) {
            uint32_t v;
            std::memcpy(&v, bytes + 4 * size_t(x), 4);
            row[x] = float(v);
        }
    }
}

// How ZIP chunks are read back: the writer split the bytes into the even ones then the odd
// ones (t) and stored the differences of neighbours plus 128 (d), which is deflated.
// OpenEXR restores every byte; here only the runs of t that the wanted pieces need are
// restored (in place in d), the runs between summed to carry the running value across.
class ChunkDecoder {
  public:
    ChunkDecoder(const std::vector<Piece> &pieces, size_t lineBytes, int width)
        : pieces(pieces), lineBytes(lineBytes), width(width) {}

    // Decode a chunk of `lines` rows, the first of which is row `row` of the planes: data is
    // the chunk as stored, raw when it is not smaller than the rows it holds.
    void Decode(const char *data, size_t size, int row, int lines, bool zip) {
        size_t n = lineBytes * size_t(lines);
        if (!zip || size == n) {
            if (size != n) throw std::runtime_error("a chunk has the wrong size");
            for (int line = 0; line < lines; ++line)
                for (const Piece &piece : pieces)
                    StoreRow(reinterpret_cast<const unsigned char *>(data) +
                                 size_t(line) * lineBytes + piece.offset,
                             piece.type, width,
                             piece.plane + size_t(row + line) * size_t(width));
            return;
        }
        if (size > n) throw std::runtime_error("a chunk is larger than its rows");
        buffer.resize(n);
        unsigned char *d = buffer.data();
        if (!inflater.Inflate(data, size, d, n))
            throw std::runtime_error("a ZIP chunk does not inflate to its rows");

        // Offsets and sizes are even (2- and 4-byte values), so a piece at offset a of n
        // bytes is t[a/2, a/2 + bytes/2) (even bytes) and t[n/2 + a/2, ...) (odd bytes).
        size_t half = n / 2, cursor = 0;
        uint8_t value = 128;  // t[-1]: t[0] = d[0]
        auto restore = [&](size_t begin, size_t end) {
            size_t skipped = begin - cursor;
            value = uint8_t(value + ByteSum(d + cursor, skipped) - (skipped & 1) * 128);
            value = RestoreRun(d + begin, end - begin, value);
            cursor = end;
        };
        for (size_t base : {size_t(0), half})
            for (int line = 0; line < lines; ++line)
                for (const Piece &piece : pieces) {
                    size_t begin = base + (size_t(line) * lineBytes + piece.offset) / 2;
                    // A channel asked for twice (two planes) is restored once.
                    if (begin < cursor) continue;
                    restore(begin, begin + piece.bytes / 2);
                }

        widened.resize(lineBytes);
        for (int line = 0; line < lines; ++line)
            for (const Piece &piece : pieces) {
                size_t at = (size_t(line) * lineBytes + piece.offset) / 2;
                const unsigned char *even = d + at, *odd = d + half + at;
                float *planeRow = piece.plane + size_t(row + line) * size_t(width);
                // Float rows are put together in place; others widened from a copy.
                unsigned char *bytes = piece.type == Imf::FLOAT
                                           ? reinterpret_cast<unsigned char *>(planeRow)
                                           : widened.data();
                Interleave(even, odd, piece.bytes / 2, bytes);
                if (piece.type != Imf::FLOAT) StoreRow(bytes, piece.type, width, planeRow);
            }
    }

  private:
    const std::vector<Piece> &pieces;
    size_t lineBytes;
    int width;
    Inflater inflater;
    std::vector<unsigned char> buffer, widened;
};

// Our decoder, when the file is one it reads: scanline, uncompressed or ZIP/ZIPS, every
// target's channel present. False otherwise (nothing read).
bool ReadChunks(Imf::InputFile &file, const std::vector<ExrTarget> &targets) {
    if constexpr (std::endian::native != std::endian::little) return false;
    const Imf::Header &header = file.header();
    // Tiled and deep parts are OpenEXR's (its InputFile composites deep samples).
    if (header.hasTileDescription() || (header.hasType() && Imf::isDeepData(header.type())))
        return false;
    Imf::Compression compression = header.compression();
    int chunkLines;
    if (compression == Imf::NO_COMPRESSION || compression == Imf::ZIPS_COMPRESSION)
        chunkLines = 1;
    else if (compression == Imf::ZIP_COMPRESSION)
        chunkLines = 16;
    else
        return false;

    const Imath::Box2i window = header.dataWindow();
    int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
    // A line of a chunk holds each channel's row in turn, in the channel list's order.
    std::vector<Piece> pieces;
    size_t lineBytes = 0;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
        const Imf::Channel &channel = it.channel();
        if (channel.type != Imf::HALF && channel.type != Imf::FLOAT &&
            channel.type != Imf::UINT)
            return false;
        size_t bytes = size_t(width) * (channel.type == Imf::HALF ? 2 : 4);
        for (const ExrTarget &target : targets)
            if (target.plane && target.channel == it.name())
                pieces.push_back({lineBytes, bytes, channel.type, target.plane});
        lineBytes += bytes;
    }
    std::sort(pieces.begin(), pieces.end(),
              [](const Piece &a, const Piece &b) { return a.offset < b.offset; });

    // Chunks are fetched one at a time (the file is one stream) and decoded in parallel.
    int chunks = (height + chunkLines - 1) / chunkLines;
    int threads = std::clamp(int(std::thread::hardware_concurrency()), 1, std::min(chunks, 16));
    std::atomic<int> next{0};
    std::atomic<bool> failed{false};
    std::mutex fileMutex;
    std::exception_ptr error;
    bool zip = compression != Imf::NO_COMPRESSION;
    auto work = [&] {
        try {
            ChunkDecoder decoder(pieces, lineBytes, width);
            std::vector<char> stored;
            for (int chunk = next++; chunk < chunks && !failed; chunk = next++) {
                int row = chunk * chunkLines, lines = std::min(chunkLines, height - row);
                {
                    std::lock_guard<std::mutex> lock(fileMutex);
                    const char *data = nullptr;
                    int size = 0;
                    file.rawPixelData(window.min.y + row, data, size);
                    if (size < 0 || !data) throw std::runtime_error("a chunk is missing");
                    stored.assign(data, data + size);
                }
                decoder.Decode(stored.data(), stored.size(), row, lines, zip);
            }
        } catch (...) {
            std::lock_guard<std::mutex> lock(fileMutex);
            if (!failed.exchange(true)) error = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    try {
        pool.reserve(size_t(threads));
        for (int t = 1; t < threads; ++t) pool.emplace_back(work);
    } catch (const std::exception &) {
        // Fewer threads than asked for: those started and this one do the work.
    }
    work();
    for (std::thread &thread : pool) thread.join();
    if (error) std::rethrow_exception(error);
    return true;
}

// OpenEXR's own reader, straight into the planes, decompressing on every core. File: an
// Imf::InputFile, or an Imf::InputPart for a part other than the first.
template <typename File>
void ReadWithOpenExr(File &file, const std::vector<ExrTarget> &targets) {
    static std::once_flag threads;
    std::call_once(threads, [] {
        Imf::setGlobalThreadCount(int(std::max(1u, std::thread::hardware_concurrency())));
    });
    const Imath::Box2i window = file.header().dataWindow();
    size_t row = size_t(window.max.x - window.min.x + 1) * sizeof(float);
    Imf::FrameBuffer buffer;
    for (const ExrTarget &target : targets) {
        // A frame buffer holds one slice per name: a channel's other planes are copied.
        if (!target.plane || buffer.findSlice(target.channel)) continue;
        // OpenEXR addresses pixel (x, y) of the data window at base + x xStride + y yStride.
        char *base = reinterpret_cast<char *>(target.plane) -
                     std::ptrdiff_t(window.min.x) * std::ptrdiff_t(sizeof(float)) -
                     std::ptrdiff_t(window.min.y) * std::ptrdiff_t(row);
        buffer.insert(target.channel, Imf::Slice(Imf::FLOAT, base, sizeof(float), row));
    }
    file.setFrameBuffer(buffer);
    file.readPixels(window.min.y, window.max.y);
    size_t planeSize = row / sizeof(float) * size_t(window.max.y - window.min.y + 1);
    for (const ExrTarget &target : targets)
        for (const ExrTarget &first : targets) {
            if (&first == &target) break;
            if (target.plane && first.plane && first.channel == target.channel) {
                if (first.plane != target.plane)
                    std::copy_n(first.plane, planeSize, target.plane);
                break;
            }
        }
}

}  // namespace

namespace {

// Whether the data window is x, y, width, height and no channel is subsampled; throws for a
// target's channel the header does not have.
bool Readable(const Imf::Header &header, int x, int y, int width, int height,
              const std::vector<ExrTarget> &targets) {
    const Imath::Box2i window = header.dataWindow();
    if (window.min.x != x || window.min.y != y || window.max.x - window.min.x + 1 != width ||
        window.max.y - window.min.y + 1 != height)
        return false;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it)
        if (it.channel().xSampling != 1 || it.channel().ySampling != 1) return false;
    for (const ExrTarget &target : targets)
        if (target.plane && !header.channels().findChannel(target.channel))
            throw std::runtime_error(fmt::format("it has no channel '{}'", target.channel));
    return true;
}

}  // namespace

bool ReadExrChannels(const std::string &path, int x, int y, int width, int height,
                     const std::vector<ExrTarget> &targets, ExrDecoder decoder, int part) {
    try {
        // A later part through OpenEXR's reader: ours decodes single-part files.
        if (part != 0) {
            Imf::MultiPartInputFile file(path.c_str());
            Imf::InputPart in(file, part);
            if (!Readable(in.header(), x, y, width, height, targets)) return false;
            ReadWithOpenExr(in, targets);
            return true;
        }
        Imf::InputFile file(path.c_str());
        if (!Readable(file.header(), x, y, width, height, targets)) return false;
        if (decoder == ExrDecoder::OpenExr || !ReadChunks(file, targets))
            ReadWithOpenExr(file, targets);
    } catch (const std::exception &e) {
        throw Error(fmt::format("cannot read '{}': {}", path, e.what()), ErrorKind::Io);
    }
    return true;
}

bool ReadExrFrameChannels(const std::string &path, const ImageHeader &header,
                          const std::vector<ExrTarget> &targets, ExrDecoder decoder) {
    if (header.channelSources.empty())
        return ReadExrChannels(path, header.x, header.y, header.width, header.height, targets,
                               decoder, header.part);
    // The targets by the part that stores them, under their names there.
    std::map<int, std::vector<ExrTarget>> byPart;
    for (const ExrTarget &target : targets) {
        auto it =
            std::find(header.channelNames.begin(), header.channelNames.end(), target.channel);
        if (it == header.channelNames.end())
            throw Error(
                fmt::format("cannot read '{}': it has no channel '{}'", path, target.channel),
                ErrorKind::Io);
        const ImageHeader::ChannelSource &source =
            header.channelSources[it - header.channelNames.begin()];
        byPart[source.part].push_back({source.name, target.plane});
    }
    for (const auto &[part, partTargets] : byPart)
        if (!ReadExrChannels(path, header.x, header.y, header.width, header.height, partTargets,
                             decoder, part))
            return false;
    return true;
}

}  // namespace mcd::io
