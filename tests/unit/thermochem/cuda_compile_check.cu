// Compile-only check that every thermochemistry kernel header is valid device code (DEM_HD
// = __host__ __device__ under nvcc). Built when the CUDA backend is enabled; never run here.
#include <coredem/dem/kernels/clg_char_gasification.h>
#include <coredem/dem/kernels/clg_oc_reduction.h>
#include <coredem/dem/kernels/conduction_contact.h>
#include <coredem/dem/kernels/conduction_gas_lens.h>
#include <coredem/dem/kernels/convection.h>
#include <coredem/dem/kernels/nasa7.h>
#include <coredem/dem/kernels/particle_energy.h>
#include <coredem/dem/kernels/radiation.h>
#include <coredem/dem/kernels/reaction_enthalpy.h>
#include <coredem/dem/kernels/reaction_generic.h>
#include <coredem/dem/kernels/species_particle.h>
#include <coredem/dem/kernels/wall_conduction.h>
#include <coredem/dem/kernels/wgs.h>

namespace k = coredem::dem::kernels;

__global__ void thermochemKernelsCompileCheck(const double* in, double* out, int n) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) {
    return;
  }
  const double t = in[i];
  double acc = 0.0;
  k::ConvectionParams cp;
  k::GasState g{1.0, 1.8e-5, 0.03, 1000.0, 300.0, 0.9};
  acc += k::convection(cp, g, 1e-3, 0.5, t).heat;
  acc += k::contactConductionHeat(1.0, 2.0, 1e-3, 1e-3, 1.99e-3, t, 300.0);
  k::GasLensParams lp;
  acc += k::gasLensHeat(lp, 0.05, 1e-3, 1e-3, 2.01e-3, t, 300.0);
  k::WallConductionParams wp;
  acc += k::wallConductionHeat(wp, 1.0, 1.0, 0.03, 1e-3, 0.99e-3, 300.0, t);
  acc +=
      k::radiationHeat(0.8, 1e-3, k::radiationEnvironmentTemperature(0.9, 1000.0, 2.0 * t, 2), t);
  acc += k::nasa7EnthalpyMolar(k::Species::Fe3O4, t) + k::reactionEnthalpy(k::ClgReaction::R4, t);
  k::HeterogeneousReaction r;
  r.n = 1;
  r.A = 1.0;
  const double solid[1] = {1.0};
  acc += k::heterogeneousExtentRate(r, t, nullptr, solid, 1e-3);
  double pBar[k::kGasSpeciesCount] = {0.1, 0.1, 0.1, 0.5, 0.2};
  acc += k::charGasification(k::CharGasificationParams{}, t, pBar, 1e-9, 2e-9).heat;
  const double x[3] = {0.6, 0.0, 0.4};
  acc += k::ocReduction(k::OcReductionParams{}, t, 1e-6, x, 1.0, 1.0).heat;
  // The engine's hoisted kernels with combined ΔH_r polynomials (built on the device here only
  // to compile combineReactionEnthalpy for it; the engine builds them on the host).
  const k::ReactionEnthalpyPoly dh[2] = {
      k::combineReactionEnthalpy(k::clgStoichiometry(k::ClgReaction::R4)),
      k::combineReactionEnthalpy(k::clgStoichiometry(k::ClgReaction::R5))};
  acc += k::reactionEnthalpy(dh[0], t);
  acc += k::charGasificationHoisted(k::CharGasificationParams{}, dh, t, pBar, 1e-9, 2e-9).heat;
  acc += k::ocReductionHoisted(k::OcReductionParams{}, dh, t, 1e-6, x, 1.0, 1.0).heat;
  const double y[k::kGasSpeciesCount] = {0.2, 0.1, 0.01, 0.3, 0.39};
  acc += k::wgsCellSources(k::WgsParams{}, t, 0.9, 0.3, y, 1e-3).heatSource;
  double m = 1e-6;
  double xs[2] = {0.5, 0.5};
  const double md[2] = {-1e-9, 0.0};
  acc += k::updateParticleSpecies(m, xs, md, 2, 1e-3) + k::shrinkingDiameter(m, 1500.0);
  k::ParticleHeatSources s;
  s.convection = acc;
  out[i] = k::particleTemperatureEuler(t, s, 1e-6, 800.0, 1e-5);
}
