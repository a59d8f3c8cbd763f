// The layer between a frame and a method's GPU pipeline (host/methods/): which layer feeds
// which input, the method's typed parameters with their defaults, and its CPU reference's
// stages. One front end a method (method_<name>.cpp); mcd::Method wraps them.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "host/methods/run_setup.h"
#include "host/methods/staged_run.h"
#include "host/vk/context.h"
#include "host/vk/recorder.h"
#include "mcdenoise/mcdenoise.h"

namespace mcd::api {

// The frame's layers as a method reads them. A layer is checked for NaN/Inf on its first
// read: refused (naming the layer and the first pixel) or replaced by 0 with a warning,
// by the non-finite policy. Demodulation overrides layers with its own images.
class Inputs {
  public:
    Inputs(const Frame &frame, bool refuseNonFinite, std::string method);
    // The window [x0, x1) x [y0, y1) of `parent` (a tile with its halo): each layer is
    // read (and checked, once, whole) from the parent and cropped on first use.
    Inputs(Inputs &parent, int x0, int y0, int x1, int y1);

    // The frame's file, or "the frame" for one built in memory (what messages start with).
    const std::string &Path() const { return frame.path.empty() ? kInMemory : frame.path; }
    // The frame itself (what a front end's Missing reads; a tile's is the whole frame).
    const mcd::Frame &Source() const { return frame; }
    int Width() const { return width; }
    int Height() const { return height; }
    // A window's origin in its whole frame and that frame's size (a frame: 0, 0 and its own).
    int OriginX() const { return parent ? parent->OriginX() + x0 : 0; }
    int OriginY() const { return parent ? parent->OriginY() + y0 : 0; }
    int FrameWidth() const { return parent ? parent->FrameWidth() : width; }
    int FrameHeight() const { return parent ? parent->FrameHeight() : height; }
    bool Has(const std::string &layer) const;
    const Image &Get(const std::string &layer);
    // Replace a layer for the rest of the run (checked like the frame's own on read).
    void Override(const std::string &layer, Image image);
    // Replace a layer by another layer of these inputs, read in its place (not copied) and
    // named by its identity, until the layer is replaced again. The layer follows its
    // source: a later replacement of the source is read through it too (a copy would not).
    void Alias(const std::string &layer, const std::string &source);
    // What a layer's replacement moves aside (ScopedOverrides): its own image where it has
    // one (a repaired, demodulated or cropped layer, or an earlier override; none: the
    // frame's or the parent's) or the layer it was read from, whether it was checked, and
    // its identity.
    struct Held {
        std::optional<Image> image;
        std::optional<std::string> alias;
        bool checked = false, crop = false;
        std::optional<std::string> id;
    };
    // Moves the layer's own image and state out (read, and so checked, first). The layer's
    // own entry stays, emptied, so that references from Get survive Override or Put into
    // it; follow Take by Override, Alias or Put before reading the layer.
    Held Take(const std::string &layer);
    // Puts back what Take moved out, replacing whatever the layer is now.
    void Put(const std::string &layer, Held held);
    // The layer's identity in a memo key (RunMemo): the hash of its values, made once and
    // kept until the layer is replaced; a window's crop of its parent's layer is named by
    // the parent's identity and the window, so no crop is hashed again.
    const std::string &LayerId(const std::string &layer);
    // The names of the frame's layers, the overrides and the aliases, sorted.
    std::vector<std::string> Names() const;
    // Work shared between runs on these inputs (auto's candidates and probes;
    // RunSetup::memo), and on the windows made of them (a tile's: keys name their content).
    void SetMemo(RunMemo *shared) { memo = shared; }
    RunMemo *Memo() const { return memo; }

    std::vector<std::string> warnings;

  private:
    static inline const std::string kInMemory = "the frame";
    const Frame &frame;
    bool refuseNonFinite;
    std::string method;
    int width, height;
    Inputs *parent = nullptr;  // a window's parent, and the window's origin in it
    RunMemo *memo = nullptr;
    int x0 = 0, y0 = 0;
    std::map<std::string, Image> overrides;  // demodulated or repaired layers, or crops
    std::map<std::string, bool> checked;
    std::set<std::string> crops;             // overrides that are crops of the parent's layer
    std::map<std::string, std::string> ids;  // LayerId's, dropped when a layer is replaced
    std::map<std::string, std::string> aliases;  // layers read from another (Alias)
};

// Layers of `inputs` replaced for a scope, each put back as it was when the scope ends,
// however it ends. A reference from Get to a layer's own image (an override, a repair or a
// crop) made before the scope stays valid and sees the scope's replacement in it (empty
// while aliased); one to a layer the scope gave its first override dangles after it.
class ScopedOverrides {
  public:
    explicit ScopedOverrides(Inputs &inputs) : inputs(inputs) {}
    ScopedOverrides(const ScopedOverrides &) = delete;
    ScopedOverrides &operator=(const ScopedOverrides &) = delete;
    ~ScopedOverrides() {
        for (auto it = saved.rbegin(); it != saved.rend(); ++it)
            inputs.Put(it->first, std::move(it->second));
    }
    // The layer's image and state moved aside, not copied: a frame's layer is not held
    // twice, and its identity is not hashed again when it comes back.
    void Override(const std::string &layer, Image image) {
        Hold(layer);
        inputs.Override(layer, std::move(image));
    }

    // The layer read from `source` of the same inputs for the scope, without a copy.
    void Alias(const std::string &layer, const std::string &source) {
        Hold(layer);
        inputs.Alias(layer, source);
    }

  private:
    // The slot made first, then the layer moved into it: no allocation after Take, so
    // nothing moved out is lost to an exception.
    void Hold(const std::string &layer) {
        saved.emplace_back(layer, Inputs::Held{});
        try {
            saved.back().second = inputs.Take(layer);
        } catch (...) {
            saved.pop_back();
            throw;
        }
    }

    Inputs &inputs;
    std::vector<std::pair<std::string, Inputs::Held>> saved;
};

// A parameter bound to a field of the options struct O: O's initializers are the defaults.
template <class O>
struct ParamDef {
    ParamInfo info;
    std::function<ParamValue(const O &)> get;
    std::function<void(O &, const ParamValue &)> set;
};

template <class O>
ParamDef<O> FloatParam(std::string name, std::string help, float O::*field, double min,
                       double max) {
    ParamInfo info{std::move(name), ParamType::Float, std::move(help), ParamValue(), min, max};
    return {info, [field](const O &o) { return ParamValue(o.*field); },
            [field](O &o, const ParamValue &v) { o.*field = std::get<float>(v); }};
}

template <class O>
ParamDef<O> IntParam(std::string name, std::string help, int O::*field, double min,
                     double max) {
    ParamInfo info{std::move(name), ParamType::Int, std::move(help), ParamValue(), min, max};
    return {info, [field](const O &o) { return ParamValue(o.*field); },
            [field](O &o, const ParamValue &v) { o.*field = std::get<int>(v); }};
}

template <class O>
ParamDef<O> BoolParam(std::string name, std::string help, bool O::*field) {
    ParamInfo info{std::move(name), ParamType::Bool, std::move(help)};
    return {info, [field](const O &o) { return ParamValue(o.*field); },
            [field](O &o, const ParamValue &v) { o.*field = std::get<bool>(v); }};
}

template <class O>
ParamDef<O> ChoiceParam(std::string name, std::string help, std::string O::*field,
                        std::vector<std::string> choices) {
    ParamInfo info{std::move(name), ParamType::String, std::move(help)};
    info.choices = std::move(choices);
    return {info, [field](const O &o) { return ParamValue(o.*field); },
            [field](O &o, const ParamValue &v) { o.*field = std::get<std::string>(v); }};
}

// A choice bound to a field of another type (an enum, a bool): each name stands for one
// value, and the parameter reads as the name of the field's value.
template <class O, class T>
ParamDef<O> EnumParam(std::string name, std::string help, T O::*field,
                      std::vector<std::pair<std::string, T>> choices) {
    ParamInfo info{std::move(name), ParamType::String, std::move(help)};
    for (const auto &choice : choices) info.choices.push_back(choice.first);
    auto named =
        std::make_shared<const std::vector<std::pair<std::string, T>>>(std::move(choices));
    std::string param = info.name;
    return {info,
            [field, named, param](const O &o) {
                for (const auto &[choice, value] : *named)
                    if (o.*field == value) return ParamValue(choice);
                throw Error(param + " holds a value none of its choices names",
                            ErrorKind::Internal);
            },
            [field, named](O &o, const ParamValue &v) {
                for (const auto &[choice, value] : *named)
                    if (choice == std::get<std::string>(v)) o.*field = value;
            }};
}

// A parameter of a struct I held as O::*inner (the method's parameters, host/params/).
template <class O, class I>
ParamDef<O> Nested(I O::*inner, ParamDef<I> def) {
    return {def.info, [inner, get = def.get](const O &o) { return get(o.*inner); },
            [inner, set = def.set](O &o, const ParamValue &v) { set(o.*inner, v); }};
}

// What a method needs to run in tiles (host/api/tiled_run.h), with its current parameters.
struct TileNeeds {
    // "" when an output pixel depends only on input pixels within `reach` (each axis) and
    // on frame-wide quantities ForTiles fixes, so that tiles with that halo reproduce the
    // untiled run bit for bit; else why not (the method then runs whole when it fits).
    std::string notLocal;
    int reach = 0;
    std::string reachText;  // what the reach is made of, for the plan
    int align = 1;          // windows start at multiples of this (a coarser grid's step)
    // GPU memory per pixel of a window, in all and in the largest single binding, and what
    // a run holds whatever its size (buffers bounded by the binding), about.
    double bytesPerPixel = 0, bindingBytesPerPixel = 0, fixedBytes = 0;
    // The widest window the method can run (0: any), for buffers that grow with a row.
    int maxWidth = 0;
    // Of `reach`, what the method's last step adds (0: none): a host pass over its output
    // and input, pixel by pixel within this reach (the local mean's restore), that a tiled
    // run makes once on the assembled frame (FrontEnd::Finish), so that no halo holds it.
    int finishReach = 0;
    // Whether the method's variants take each other's work from the run memo window by
    // window where their tiles lie alike (rhf's selections and aggregations): auto then
    // plans them on one tile plan, their needs widened together.
    bool sharesByWindow = false;
};

class FrontEnd {
  public:
    virtual ~FrontEnd() = default;
    virtual std::unique_ptr<FrontEnd> Clone() const = 0;

    virtual const std::string &Name() const = 0;
    virtual std::string Summary() const = 0;
    virtual const std::vector<ParamInfo> &Params() const = 0;
    // The value has the parameter's type and lies in its range (mcd::Method checked it).
    virtual void Set(const std::string &name, const ParamValue &value) = 0;
    virtual ParamValue Get(const std::string &name) const = 0;

    // Why the frame lacks what the method needs with its parameters ("" when it has it).
    virtual std::string Missing(const Frame &frame) const { return ""; }
    // The layers the method may read (ReadOptions::layers); empty: it may read any.
    virtual std::vector<std::string> Uses() const { return {}; }
    // Why the method cannot run on color divided by `layer` ("" when it can).
    virtual std::string Undemodulable(const Frame &frame, const std::string &layer) const {
        return "";
    }

    virtual Result Run(vk::Context &context, Inputs &inputs, const RunOptions &run) const = 0;
    // Makes ahead the kernels Run will record on these inputs (Context::PrepareKernel), so
    // that they build beside earlier work (auto's other candidates): only kernels the run
    // records, none for a layer the frame lacks. Default: none (each builds when recorded).
    virtual void PrepareKernels(vk::Context &context, Inputs &inputs) const {}

    // Tiling: the reach and memory per pixel on these inputs (default: not tile-local).
    virtual TileNeeds Tiling(vk::Context &context, Inputs &inputs) const {
        TileNeeds needs;
        needs.notLocal = Name() + " declares no reach";
        return needs;
    }
    // A copy that computes, on any window of `whole`, what the run on `whole` computes
    // there: frame-wide quantities (means, totals, scale counts, decisions) fixed from
    // `whole`, measured on this device where they need it.
    virtual std::unique_ptr<FrontEnd> ForTiles(vk::Context &context, Inputs &whole) const {
        return Clone();
    }
    // The last step TileNeeds::finishReach names, made on the output assembled from the
    // tiles (`whole`: the frame's inputs). RunTiled calls LeaveFinishToWhole on ForTiles'
    // copy, whose Run then leaves the step out, and calls Finish on it once after the tiles.
    virtual void Finish(vk::Context &context, Inputs &whole, Result *result) const {}
    void LeaveFinishToWhole() { finishWhole = true; }
    bool FinishesWhole() const { return finishWhole; }
    // A copy for auto's probe of this run (`onHalf`: its run on half0, another estimate of
    // the frame; else on the perturbed colour), with decisions the run takes on `run` (its
    // frame as given) kept, so that the probe does not flip between branches the run did not
    // take (bayes's --zeros restore, rhf's cuts). Null: the probe runs as the run does.
    // rhf's probe makes the run's cuts (the pixels, and the lights a rim's median leaves out)
    // on its own colour, whatever its variance: a host CPU step with no CPU twin of its own;
    // its tests hold the probe on the run's own colour to the run's bits, whole and tiled.
    virtual std::unique_ptr<FrontEnd> ForProbe(vk::Context &context, Inputs &run,
                                               bool onHalf) const {
        return nullptr;
    }
    virtual std::vector<Stage> Reference(vk::Context &context, Inputs &inputs) const = 0;

  protected:
    // Set by LeaveFinishToWhole: Run leaves out the step Finish makes.
    bool finishWhole = false;
};

// A front end whose parameters are the fields of O, by the table `defs`.
template <class O>
class FrontEndOf : public FrontEnd {
  public:
    FrontEndOf(std::string name, std::vector<ParamDef<O>> defs) : name(std::move(name)) {
        auto built = std::make_shared<Table>();
        built->defs = std::move(defs);
        for (ParamDef<O> &def : built->defs) {
            def.info.defaultValue = def.get(O());
            def.info.method = this->name;
            built->infos.push_back(def.info);
        }
        table = std::move(built);
    }
    const std::string &Name() const override { return name; }
    const std::vector<ParamInfo> &Params() const override { return table->infos; }
    void Set(const std::string &param, const ParamValue &value) override {
        Def(param).set(options, value);
    }
    ParamValue Get(const std::string &param) const override { return Def(param).get(options); }

    O options;

  private:
    const ParamDef<O> &Def(const std::string &param) const {
        for (const ParamDef<O> &def : table->defs)
            if (def.info.name == param) return def;
        throw Error(name + " has no parameter '" + param + "'", ErrorKind::InvalidArgument);
    }
    struct Table {
        std::vector<ParamDef<O>> defs;
        std::vector<ParamInfo> infos;
    };
    std::string name;
    std::shared_ptr<const Table> table;  // shared by copies: the table never changes
};

// Each method's front end is made by its factory (method_<name>.cpp), listed in the
// registry (registry.h).

// What every pipeline is told besides the method's parameters: the stages and progress the
// caller asked for, and where a tile's window lies in its frame.
RunSetup SetupFor(const Inputs &inputs, const RunOptions &run);

// The public result from a pipeline's (sliced from BayesResult, RhfResult, ...).
Result ResultOf(MethodResult &&run);

// A parameter's value as text: true/false, the number, or the string itself.
std::string ParamValueText(const ParamValue &value);

// Words joined as a sentence lists them, an empty one said as '': "a", "a or b", "a, b or c".
std::string OrList(const std::vector<std::string> &words);

// The frame's samples per pixel: the median of its spp layer (rounded) where it has one,
// else what its metadata states (host/common/samples.h), else 0 (unknown).
int FrameSamplesPerPixel(Inputs &inputs);

}  // namespace mcd::api
