// `mcdenoise bench kernels` end to end on a small frame: its CSV carries each kernel's
// operation count and how that count bounds the work, and the table marks the bounds.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "harness/tool.h"

namespace mcd::test {
namespace {

std::vector<std::string> Fields(const std::string &line) {
    std::vector<std::string> fields;
    std::stringstream in(line);
    for (std::string field; std::getline(in, field, ',');) fields.push_back(field);
    if (!line.empty() && line.back() == ',') fields.push_back("");
    return fields;
}

TEST(BenchKernelsCli, CsvGivesEachKernelsCountAndItsBound) {
    ToolDir dir("bench_kernels");
    ToolResult r = dir.Run(
        "bench kernels --size 24x16 --spp 2 --methods awr,nfor --repeat 1 --calibration-mb 4 "
        "--share 0 --csv k.csv");
    ASSERT_EQ(r.code, 0) << r.All();
    std::ifstream csv(dir.Path("k.csv"));
    std::string device, header;
    std::getline(csv, device);
    std::getline(csv, header);
    EXPECT_EQ(header,
              "method,kernel,dispatches,bytes_per_px,flops_per_px,gpu_ms,gbs,gflops,"
              "roofline_fraction,flops_bound");
    std::map<std::string, std::vector<std::string>> rows;  // kernel -> fields
    for (std::string line; std::getline(csv, line);) {
        std::vector<std::string> f = Fields(line);
        ASSERT_EQ(f.size(), 10u) << line;
        rows[f[1]] = f;
    }
    ASSERT_TRUE(rows.count("wavelet_analyze") && rows.count("nfor_regress") &&
                rows.count("nfor_clamp"))
        << r.out;
    EXPECT_GT(std::stod(rows["wavelet_analyze"][4]), 0);
    EXPECT_EQ(rows["wavelet_analyze"][9], "exact");
    EXPECT_GT(std::stod(rows["nfor_regress"][4]), 0);
    EXPECT_EQ(rows["nfor_regress"][9], "at_most");
    // No formula: no count, no bound.
    EXPECT_EQ(rows["nfor_clamp"][4], "");
    EXPECT_EQ(rows["nfor_clamp"][9], "");
    EXPECT_NE(r.out.find("<="), std::string::npos) << r.out;
}

}  // namespace
}  // namespace mcd::test
