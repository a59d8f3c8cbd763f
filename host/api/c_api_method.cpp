// The C API's methods, runs and results (include/mcdenoise/mcdenoise_c.h).

#include <variant>

#include <fmt/format.h>

#include "host/api/c_api.h"
#include "host/api/front_end.h"
#include "host/api/views.h"

using namespace mcd;
using namespace mcd::api;

namespace {

template <class Value>
bool SetParam(MCDMethod method, const char *param, const Value &value) {
    return Guarded(false, [&] {
        Require(method, "the method");
        Require(param, "the parameter's name");
        method->method.Set(param, value);
        return true;
    });
}

const char *Line(const std::vector<std::string> &lines, int index) {
    return index >= 0 && size_t(index) < lines.size() ? lines[size_t(index)].c_str() : nullptr;
}

// The progress function as RunOptions' progress and cancel; `stop` latches a false.
void Monitor(MCDMethod method, bool &stop, RunOptions &run) {
    if (!method->progress) return;
    MCDProgressFunction function = method->progress;
    void *user = method->progressUser;
    run.progress = [function, user, &stop](const std::string &stage, int done, int total) {
        if (!stop && !function(user, stage.c_str(), done, total)) stop = true;
    };
    run.cancel = [function, user, &stop] {
        if (!stop && !function(user, "", 0, 0)) stop = true;
        return stop;
    };
}

}  // namespace

extern "C" {

bool mcdSetMethodBool(MCDMethod method, const char *param, bool value) {
    return SetParam(method, param, value);
}

bool mcdSetMethodInt(MCDMethod method, const char *param, int value) {
    return SetParam(method, param, value);
}

bool mcdSetMethodFloat(MCDMethod method, const char *param, double value) {
    return SetParam(method, param, value);
}

bool mcdSetMethodString(MCDMethod method, const char *param, const char *value) {
    return Guarded(false, [&] {
        Require(value, "the value");
        return SetParam(method, param, std::string(value));
    });
}

bool mcdSetMethodText(MCDMethod method, const char *param, const char *text) {
    return Guarded(false, [&] {
        Require(method, "the method");
        Require(param, "the parameter's name");
        Require(text, "the text");
        method->method.SetText(param, text);
        return true;
    });
}

int mcdGetMethodParamCount(MCDMethod method) {
    return Guarded(0, [&] {
        Require(method, "the method");
        return int(method->method.Params().size());
    });
}

const char *mcdGetMethodParamName(MCDMethod method, int index) {
    return Guarded<const char *>(nullptr, [&]() -> const char * {
        Require(method, "the method");
        const std::vector<ParamInfo> &params = method->method.Params();
        if (index < 0 || size_t(index) >= params.size()) return nullptr;
        return params[size_t(index)].name.c_str();
    });
}

const char *mcdGetMethodParamText(MCDMethod method, const char *param) {
    return Guarded<const char *>(nullptr, [&] {
        Require(method, "the method");
        Require(param, "the parameter's name");
        return method->handed.Keep(api::ParamValueText(method->method.Get(param)));
    });
}

void mcdSetMethodProgressFunction(MCDMethod method, MCDProgressFunction function,
                                  void *userPtr) {
    Guarded(false, [&] {
        Require(method, "the method");
        method->progress = function;
        method->progressUser = userPtr;
        return true;
    });
}

MCDResult mcdRunMethod(MCDMethod method, MCDDevice device, MCDFrame frame,
                       const MCDView *output) {
    return Guarded<MCDResult>(nullptr, [&] {
        Require(method, "the method");
        Require(device, "the device");
        Require(frame, "the frame");
        RunOptions run;
        // A view given without its memory is a mistake, not "no output view" (NULL is).
        if (output && !output->data)
            throw Error(
                "the output view has no data (pass NULL to keep the result in the "
                "MCDResult)",
                ErrorKind::InvalidArgument);
        if (output) run.output = OutputViewOf(*output);
        bool stop = false;
        Monitor(method, stop, run);
        auto *result = new MCDResultImpl;
        try {
            result->result = method->method.Run(device->device, frame->frame, run);
        } catch (...) {
            delete result;
            throw;
        }
        return result;
    });
}

void mcdReleaseResult(MCDResult result) {
    delete result;
}

const char *mcdGetResultMethod(MCDResult result) {
    return Guarded<const char *>(nullptr, [&] {
        Require(result, "the result");
        return result->result.method.c_str();
    });
}

int mcdGetResultCandidateCount(MCDResult result) {
    return result ? int(result->result.candidates.size()) : 0;
}

const char *mcdGetResultCandidate(MCDResult result, int index) {
    return result ? Line(result->result.candidates, index) : nullptr;
}

int mcdGetResultPlanCount(MCDResult result) {
    return result ? int(result->result.plan.size()) : 0;
}

const char *mcdGetResultPlanLine(MCDResult result, int index) {
    return result ? Line(result->result.plan, index) : nullptr;
}

int mcdGetResultWarningCount(MCDResult result) {
    return result ? int(result->result.warnings.size()) : 0;
}

const char *mcdGetResultWarning(MCDResult result, int index) {
    return result ? Line(result->result.warnings, index) : nullptr;
}

double mcdGetResultWallMs(MCDResult result) {
    return result ? result->result.wallMs : 0;
}

double mcdGetResultGpuMs(MCDResult result) {
    return result ? result->result.GpuMs() : 0;
}

bool mcdCopyResultImage(MCDResult result, const MCDView *output) {
    return Guarded(false, [&] {
        Require(result, "the result");
        Require(output, "the output view");
        if (result->result.image.Empty())
            throw Error("the result has no image: the run wrote it into its output view",
                        ErrorKind::InvalidArgument);
        OutputView view = OutputViewOf(*output);
        CheckView(view, "the output");
        const Result &r = result->result;
        if (r.rimPixels > 0 && view.channels == r.image.channels)
            throw Error(fmt::format("the output has no alpha channel, but alpha-rim moved "
                                    "light and alpha into {} pixel(s) of alpha 0: copy into "
                                    "{} channels, or run with alpha-rim 0 or into a "
                                    "{}-channel output view",
                                    r.rimPixels, r.image.channels + 1, r.image.channels),
                        ErrorKind::InvalidArgument);
        WriteOutput(r.image, r.alpha, view);
        return true;
    });
}

}  // extern "C"
