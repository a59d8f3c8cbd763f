#include "host/api/nfor_reference.h"

#include <algorithm>

#include "host/methods/nfor_band.h"
#include "host/methods/nfor_specks.h"

namespace mcd::api {

ref::NforParams NforReferenceParams(const NforOptions &o,
                                    const std::vector<float> &featureWeights) {
    ref::NforParams p;
    p.radius = o.radius;
    p.gatherRadius = o.gatherRadius < 0 ? o.radius : std::min(o.gatherRadius, o.radius);
    p.patchRadius = o.patchRadius;
    p.bandwidths.assign(o.bandwidths.begin(), o.bandwidths.end());
    p.alpha = o.alpha;
    p.minVariance = o.minVariance;
    p.pilotMinVariance = NforPilotMinVariance(o);
    p.demodulateDistance = !o.noDemodulatedDistance;
    p.albedoNoise = o.albedoNoise;
    p.glintNoise = o.glintNoise;
    p.ridge = o.ridge;
    p.featureWeights.assign(featureWeights.begin(), featureWeights.end());
    p.noiseRadius = o.noiseRadius;
    p.edgeNoise = !o.noEdgeNoise;
    p.sparseNoise = !o.noSparseNoise;
    p.clampEstimate = !o.clampLayer;
    p.clampLoss = o.clampLoss;
    p.noiseMinCalibration = o.noiseCalibration;
    p.fireflyThreshold = o.fireflyThreshold;
    p.fireflyRelative = o.fireflyRelative;
    p.fireflyRank = o.fireflyRank;
    p.fireflyLightEdge = o.fireflyLightEdge;
    p.fireflySum = !o.fireflyEachChannel;
    p.fireflyLine = o.fireflyLine;
    p.fireflyLoneLight = o.fireflyLoneLight;
    p.fireflyLineFloor = o.fireflyLineFloor;
    p.emitterAlbedo = o.emitterAlbedo;
    p.prefilterRadius = o.prefilterRadius;
    p.prefilterPatch = o.prefilterPatch;
    p.prefilterBandwidth = o.prefilterBandwidth;
    p.sureRadius = o.sureRadius;
    p.pilotBandwidths.assign(o.pilotBandwidths.begin(), o.pilotBandwidths.end());
    p.pilotAlpha = o.pilotAlpha;
    p.pilotWideRadius = o.pilotWideRadius;
    p.noisyRadius = o.noisyRadius;
    const NforOptions noisy = NforNoisyOptions(o);
    p.noisyGatherRadius =
        noisy.gatherRadius < 0 ? noisy.radius : std::min(noisy.gatherRadius, noisy.radius);
    p.wideAgreement = o.wideAgreement;
    p.meanRadius = o.meanRadius;
    p.clampLightRadius = o.clampLightRadius;
    p.clampLightFine = o.clampLightFine;
    p.clampLightReach = o.clampLightReach;
    p.clampLightNoise = kClampLightNoise;
    p.rareLightShare = o.rareLightShare;
    p.rareLightRatio = o.rareLightRatio;
    p.rareLightPair = o.rareLightPair;
    p.rareLightOthers = o.rareLightOthers;
    p.glintBandRadius = o.glintBandRadius;
    const NforGlintBandSettings band;
    p.glintBandSigma = band.sigma;
    p.glintBandTensorSigma = band.tensorSigma;
    p.glintBandBound = band.bound;
    p.speckRelative = o.speckRelative;
    p.exactGround = !o.noExactGround;
    p.loneHits = kNforLoneHits;
    p.loneRatio = kNforLoneRatio;
    p.loneReach = o.noLoneSampleCap ? 0 : kNforLoneReach;
    p.speckFloor = o.speckFloor;
    p.speckRank = o.speckRank;
    p.speckFlatShare = o.speckFlatShare;
    p.speckFlatRelative = o.speckFlatRelative;
    p.keptRadius = o.keptRadius;
    p.weakEmitterAlbedo = o.weakEmitterAlbedo;
    p.weakEmitterLine = o.weakEmitterLine;
    p.weakEmitterRange = o.weakEmitterRange;
    p.weakLightShare = o.weakLightShare;
    p.lightShare = o.lightShare;
    p.lineSpread = o.lineSpread;
    p.rimRatio = o.rimRatio;
    p.coarse = o.coarse;
    p.coarseRelative = o.coarseRelative;
    p.coarseNoise = o.coarseNoise;
    p.coarseGate = o.coarseGate;
    p.premultiplied = o.premultiplied;
    p.layerPasses = !o.noLayerPasses;
    p.layerNoiseCap = o.layerNoiseCap;
    p.pilotNoiseCap = o.pilotNoiseCap;
    return p;
}

}  // namespace mcd::api
