#include "host/kernels/bayes_table.h"

#include <fmt/format.h>

#include "bayes/bayes.h"
#include "bayes/table.h"
#include "bayes/table_spv.h"
#include "host/error.h"
#include "host/vk/context.h"
#include "host/vk/kernel.h"

namespace mcd {

void RecordBayesTable(vk::Context &context, vk::Recorder &recorder, const vk::Buffer &params,
                      int bands, vk::Buffer &table) {
    if (params.Bytes() < VkDeviceSize(bands) * BAYES_PARAM_STRIDE * sizeof(float) ||
        table.Bytes() < VkDeviceSize(bands) * BAYES_TABLE_SIZE * sizeof(float))
        throw Error(fmt::format("bayes table: buffers too small for {} bands", bands),
                    ErrorKind::Internal);
    const vk::Kernel &kernel = context.GetKernel({"bayes_table",
                                                  k_bayes_table_spv,
                                                  sizeof(k_bayes_table_spv),
                                                  BAYES_TABLE_BINDINGS,
                                                  sizeof(shader::BayesTablePush),
                                                  {}});
    shader::BayesTablePush push{bands};
    recorder.Dispatch(
        kernel, "bayes.table",
        {{BAYES_TABLE_PARAMS, &params, vk::Access::Read},
         {BAYES_TABLE_OUT, &table, vk::Access::Write}},
        push,
        uint32_t((BAYES_TABLE_SIZE + BAYES_TABLE_LOCAL_SIZE - 1) / BAYES_TABLE_LOCAL_SIZE),
        uint32_t(bands));
}

}  // namespace mcd
