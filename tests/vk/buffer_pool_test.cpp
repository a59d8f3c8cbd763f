// The buffer pool (host/vk/buffer_pool.h) and the staging buffers (host/vk/buffer.h): freed
// buffers reused by size, never while live, within the most the live buffers held; the
// ledger that --explain prints unchanged by reuse; transfers through the kept staging
// buffers give the bytes back.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <numeric>
#include <random>
#include <set>
#include <vector>

#include "harness/gpu_fixture.h"
#include "host/vk/buffer.h"
#include "host/vk/buffer_pool.h"
#include "host/vk/context.h"

namespace mcd::test {
namespace {

// A freed buffer's memory goes to the next buffer of the same allocation size (sizes
// rounded up to 16 bytes), and not to one of another size.
TEST(VkBufferPool, ReusesFreedBuffersOfTheSameSize) {
    vk::Context ctx(vk::ContextOptions{.pipelineThreads = 1});
    vk::Buffer other(ctx, 2000, "pool.other");
    VkBuffer first;
    {
        vk::Buffer a(ctx, 1000, "pool.a"), larger(ctx, 1024, "pool.larger");
        first = a.Handle();
    }
    EXPECT_EQ(ctx.Pool().GetStats().keptBytes, 1008u + 1024u);
    vk::Buffer same(ctx, 1001, "pool.same");  // 1001 and 1000 both allocate 1008
    EXPECT_EQ(same.Handle(), first);
    EXPECT_EQ(same.Bytes(), 1001u);
    vk::BufferPool::Stats stats = ctx.Pool().GetStats();
    EXPECT_EQ(stats.reused, 1u);
    EXPECT_EQ(stats.fresh, 3u);
    EXPECT_EQ(stats.keptBytes, 1024u);  // the larger one's memory is still kept
    EXPECT_EQ(stats.liveBytes, 1008u + 2000u);
    vk::Buffer odd(ctx, 1040, "pool.odd");  // a size kept nowhere: fresh
    EXPECT_EQ(ctx.Pool().GetStats().reused, 1u);
    EXPECT_EQ(ctx.Pool().GetStats().fresh, 4u);
}

// Live buffers never share memory: many buffers of one size alive together, freed and
// taken again in random order, each written with its own pattern and read back intact.
TEST(VkBufferPool, LiveBuffersNeverAlias) {
    vk::Context ctx(vk::ContextOptions{.pipelineThreads = 1});
    std::mt19937 rng(32);
    std::vector<std::unique_ptr<vk::Buffer>> live;
    std::vector<uint32_t> tags;
    uint32_t next = 1;
    for (int step = 0; step < 200; ++step) {
        bool make = live.size() < 3 || (live.size() < 12 && rng() % 2 == 0);
        if (make) {
            live.push_back(std::make_unique<vk::Buffer>(ctx, 4096, "pool.live"));
            tags.push_back(next++);
            live.back()->UploadFloats(std::vector<float>(1024, float(tags.back())));
        } else {
            size_t k = rng() % live.size();
            live.erase(live.begin() + long(k));
            tags.erase(tags.begin() + long(k));
        }
        std::set<VkBuffer> handles;
        for (size_t k = 0; k < live.size(); ++k) {
            EXPECT_TRUE(handles.insert(live[k]->Handle()).second) << "step " << step;
            std::vector<float> back = live[k]->DownloadFloats(1024);
            for (float v : back) ASSERT_EQ(v, float(tags[k])) << "step " << step;
        }
    }
    EXPECT_GT(ctx.Pool().GetStats().reused, 0u);
}

// The pool holds no more than the most the live buffers ever held together: a fresh
// allocation frees kept buffers of other sizes first, least recently kept first.
TEST(VkBufferPool, HoldsAtMostTheLivePeak) {
    vk::Context ctx(vk::ContextOptions{.pipelineThreads = 1});
    auto held = [&] {
        vk::BufferPool::Stats s = ctx.Pool().GetStats();
        return s.liveBytes + s.keptBytes;
    };
    { vk::Buffer a(ctx, 1 << 20, "pool.a"), b(ctx, 1 << 20, "pool.b"); }
    EXPECT_EQ(ctx.Pool().GetStats().highWater, 2u << 20);
    EXPECT_EQ(held(), 2u << 20);
    {
        // Another size: 1.5 MiB live and 2 MiB kept would exceed the 2 MiB peak, so both
        // kept buffers go, the first kept first.
        vk::Buffer c(ctx, 3 << 19, "pool.c");
        EXPECT_EQ(ctx.Pool().GetStats().freed, 2u);
        EXPECT_EQ(held(), VkDeviceSize(3) << 19);
    }
    {
        vk::Buffer e(ctx, 1 << 19, "pool.e");  // 0.5 live + 1.5 kept fit the peak: kept
        EXPECT_EQ(ctx.Pool().GetStats().freed, 2u);
        EXPECT_EQ(held(), VkDeviceSize(2) << 20);
    }
    for (int round = 0; round < 20; ++round) {
        vk::Buffer d(ctx, VkDeviceSize(round + 1) << 16, "pool.d");
        EXPECT_LE(held(), ctx.Pool().GetStats().highWater);
    }
    ctx.Pool().Trim();
    EXPECT_EQ(ctx.Pool().GetStats().keptBytes, 0u);
    EXPECT_EQ(ctx.Pool().GetStats().liveBytes, 0u);
}

// --explain's "GPU buffers" line reads the ledger: every buffer made counts as an
// allocation and live while it lives, reused or fresh, so reuse changes none of it.
TEST(VkBufferPool, LedgerCountsReusedBuffersAsAllocations) {
    vk::Context ctx(vk::ContextOptions{.pipelineThreads = 1});
    ctx.ResetLedger();
    { vk::Buffer a(ctx, 1000, "ledger.a"); }
    {
        vk::Buffer b(ctx, 1000, "ledger.b");  // the memory of a
        EXPECT_EQ(ctx.Pool().GetStats().reused, 1u);
        EXPECT_EQ(ctx.Ledger().live, 1000u);
    }
    EXPECT_EQ(ctx.Ledger().live, 0u);
    EXPECT_EQ(ctx.Ledger().peak, 1000u);
    ASSERT_EQ(ctx.Ledger().allocations.size(), 2u);
    EXPECT_EQ(ctx.Ledger().allocations[1].first, "ledger.b");
    EXPECT_EQ(ctx.Ledger().allocations[1].second, 1000u);
}

// With the pool off every freed buffer is freed at once and none is taken again.
TEST(VkBufferPool, OffFreesAtOnce) {
    vk::Context ctx(vk::ContextOptions{.pipelineThreads = 1, .keepFreedBuffers = false});
    { vk::Buffer a(ctx, 1000, "pool.a"); }
    { vk::Buffer b(ctx, 1000, "pool.b"); }
    vk::BufferPool::Stats stats = ctx.Pool().GetStats();
    EXPECT_EQ(stats.reused, 0u);
    EXPECT_EQ(stats.fresh, 2u);
    EXPECT_EQ(stats.freed, 2u);
    EXPECT_EQ(stats.keptBytes, 0u);
}

// Poisoned buffers read NaN bits until written, fresh or reused.
TEST(VkBufferPool, PoisonFillsFreshAndReusedBuffers) {
    for (bool staged : {false, true}) {
        vk::Context ctx(vk::ContextOptions{
            .pipelineThreads = 1, .poisonBuffers = true, .stageTransfers = staged});
        auto allPoison = [](const vk::Buffer &b) {
            std::vector<uint32_t> words(b.Bytes() / 4);
            b.Download(words.data(), words.size() * 4);
            for (uint32_t w : words)
                if (w != 0xffffffffu) return false;
            return true;
        };
        {
            vk::Buffer a(ctx, 64, "poison.a");
            EXPECT_TRUE(allPoison(a)) << "staged " << staged;
            a.UploadFloats(std::vector<float>(16, 0.f));
        }
        vk::Buffer b(ctx, 64, "poison.b");
        EXPECT_EQ(ctx.Pool().GetStats().reused, 1u);
        EXPECT_TRUE(allPoison(b)) << "staged " << staged;
    }
}

// Transfers through the staging buffers (the discrete GPU's path): bytes at offsets and
// across chunk boundaries come back as written, and the staging buffers are allocated a
// few times as they grow, not once per transfer.
TEST(VkStaging, TransfersReuseTheStagingBuffers) {
    vk::Context ctx(vk::ContextOptions{.pipelineThreads = 1, .stageTransfers = true});
    std::vector<uint8_t> bytes(3 * 1000 * 1000 + 5);
    std::iota(bytes.begin(), bytes.end(), uint8_t(7));
    vk::Buffer buffer(ctx, bytes.size(), "staging.target");
    for (int round = 0; round < 10; ++round) {
        buffer.Upload(bytes.data(), bytes.size());
        std::vector<uint8_t> back(bytes.size());
        buffer.Download(back.data(), back.size());
        ASSERT_EQ(back, bytes) << "round " << round;
    }
    // A part at an offset.
    std::vector<uint8_t> part(1001, 0xab);
    buffer.Upload(part.data(), part.size(), 12345);
    std::vector<uint8_t> back(1001 + 2);
    buffer.Download(back.data(), back.size(), 12344);
    EXPECT_EQ(back[0], bytes[12344]);
    for (size_t i = 1; i <= 1001; ++i) ASSERT_EQ(back[i], 0xab);
    EXPECT_EQ(back[1002], bytes[12345 + 1001]);
    EXPECT_EQ(ctx.StagingFor(false).Allocations(), 1);
    EXPECT_EQ(ctx.StagingFor(true).Allocations(), 1);
    // Larger than a chunk: in pieces through a buffer of one chunk.
    const size_t large = size_t(vk::Staging::kChunk) + 4096 + 12;
    std::vector<uint8_t> big(large);
    std::iota(big.begin(), big.end(), uint8_t(3));
    vk::Buffer target(ctx, large, "staging.large");
    target.Upload(big.data(), big.size());
    std::vector<uint8_t> bigBack(large);
    target.Download(bigBack.data(), bigBack.size());
    EXPECT_TRUE(bigBack == big);
    EXPECT_EQ(ctx.StagingFor(false).Bytes(), vk::Staging::kChunk);
    EXPECT_EQ(ctx.StagingFor(false).Allocations(), 2);
}

}  // namespace
}  // namespace mcd::test
