#pragma once
/// @file
/// Chemistry in the DEM sub-step (docs/physics.md §3.5, §4, §6; docs/thermochemistry.md), written
/// once for every backend like engine_impl.h and heat.h. Per sub-step, after the forces, the drag
/// deposition (particles sorted by PCM cell) and the heat sources, before the motion update:
///   1. rates, per particle, with the gas of its PCM cell frozen for the CFD step: one gas state
///      per cell (kernels::cellGasState: c_k = ρ_g Y_k/M_k, x_k = Y_k M_mix/M_k, the case's
///      thermodynamic pressure for x_k p): the data-defined reactions (reaction_generic.h), R1 + R2
///      (clg_char_gasification.h) and R4 + R5 (clg_oc_reduction.h) at T_p
///   2. one availability limiter per particle: every rate of the particle is scaled by the same
///      s ∈ [0, 1] so that no solid species mass goes negative within Δt and the particle does not
///      shrink below half the removal diameter (stoichiometry, hence mass balance, is kept)
///   3. species masses m_k += Δt ṁ_k (Eq. 31; inert species unchanged), m = Σ m_k, X_k = m_k/m,
///      radius from the mass at constant density (Eq. 32): the contact model uses it from the
///      next force evaluation on, the motion update of this sub-step uses the new mass
///   4. per cell (segment heads of the PCM order): Σ ṁ_gas Δt, Σ Δm_solid, Σ Q_rxn Δt, the sensible
///      heat of the transferred gas Σ ṁ_gas,i c_p,g (T_p,i − T_g) Δt (gas enters at T_p, not T_g;
///      c_p,g, T_g of the cell from the frozen gas; 0 outside the grid or without gas fields) and
///      the particle-side Σ Δm_i c_p,i T_p,i (J) and the momentum of the released gas Σ ṁ_gas,i u_i
///      Δt (N s; the gas leaves at the particle's velocity u_i of the sub-step, before the motion
///      update) added to the window accumulators (row nCells: particles outside the grid, ledgers
///      only)
///   5. after the heat module's temperature update: T += Δt Q_rxn/(m c_p) (when reaction heat is
///   on)
/// At the window end R_species = Σ ṁ Δt/(V_c t_window), Q_hom = Σ ṁ_gas c_p,g (T_p − T_g) Δt/(V_c
/// t_window), mom_p = Σ ṁ_gas u Δt/(V_c t_window) and the WGS (R3) of every cell is added
/// from the frozen gas (host, once per CFD step). A particle whose diameter fell below
/// removalFraction·d_0 stops reacting and is reported (takeRemovalRequest) so that DemSystem
/// removes it at the CFD-step boundary.
///
/// Every loop writes only its own index (gather per cell over sorted segments, no atomics), so
/// results are bitwise independent of the thread count.

#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "backend/arrays.h"
#include "backend/exec_common.h"
#include "chemistry_setup.h"
#include "coredem/dem/chemistry_options.h"
#include "coredem/dem/kernels/pressure_gradient.h"
#include "coredem/dem/kernels/species_particle.h"
#include "step_module.h"

namespace coredem::dem {

/// The reaction and enthalpy tables the rates read (device pointers).
struct ChemRateTables {
  const kernels::HeterogeneousReaction* reac;  ///< data-defined reactions
  const kernels::ReactionEnthalpyPoly* dhPoly; ///< their ΔH(T) (n = 0: constant rx.dH)
  const kernels::ReactionEnthalpyPoly* dhChar; ///< R1/R2 heats; nullptr without reaction heat
  const kernels::ReactionEnthalpyPoly* dhOc;   ///< R4/R5 heats; nullptr without reaction heat
  const double* gasM;                          ///< kg/mol per case gas species
  const double* rhoG;                          ///< per cell; nullptr without the gas state
  const double* yg;                            ///< per cell and gas species; as rhoG
};

/// Step 1 for a particle holding reactants, at T_p = tp in PCM cell `cell` (the cell's gas
/// when `cellGas`, else none: gas-dependent rates are zero): adds the rates of the data-defined
/// reactions, R1 + R2 and R4 + R5 to solidRate, gasRate (kg/s) and their heat to `heat` (W).
/// `sm`: the particle's solid species masses (kg), mi their sum; ref: chemRef of particle i.
DEM_HD_FORCEINLINE void addParticleReactionRates(const ChemParams& cp, const ChemRateTables& t,
                                                 bool cellGas, std::uint32_t cell, double tp,
                                                 double mi, const double* sm, const double* ref,
                                                 std::size_t i, double dt, double* solidRate,
                                                 double* gasRate, double& heat) {
  using namespace kernels;
  const int nG = cp.nGas;
  const HeterogeneousReaction* reac = t.reac;
  const ReactionEnthalpyPoly* dhPoly = t.dhPoly;
  const ReactionEnthalpyPoly* dhChar = t.dhChar;
  const ReactionEnthalpyPoly* dhOc = t.dhOc;
  const double* gasM = t.gasM;
  const double* rhoG = t.rhoG;
  const double* yg = t.yg;
  // Gas of the particle's PCM cell (no gas: gas-dependent rates are zero).
  double conc[kChemMaxGas];
  double pBar[kGasSpeciesCount];
  for (int k = 0; k < nG; ++k)
    conc[k] = 0.0;
  for (int k = 0; k < kGasSpeciesCount; ++k)
    pBar[k] = 0.0;
  if (cellGas) {
    // The cell's one gas state: c_k = ρ_g Y_k/M_k for the concentration rates (data-
    // defined reactions, R4/R5), x_k = Y_k M_mix/M_k and P_j = x_j p (bar) with the
    // case's thermodynamic pressure for the char rates (R1/R2).
    double x[kChemMaxGas];
    cellGasState(rhoG[cell], yg + static_cast<std::size_t>(cell) * nG, gasM, nG, x, conc);
    for (int g = 0; g < kGasSpeciesCount; ++g) {
      const int k = cp.gasIndex[g];
      if (k >= 0)
        pBar[g] = x[k] * cp.pressure * 1.0e-5;
    }
  }
  // Data-defined reactions.
  for (int a = 0; a < cp.nReactions; ++a) {
    const HeterogeneousReaction& rx = reac[a];
    const double w = heterogeneousExtentRate(rx, tp, conc, sm, dt);
    addHeterogeneousSources(rx, w, solidRate, gasRate);
    if (w != 0.0)
      heat -= (dhPoly[a].n > 0 ? reactionEnthalpy(dhPoly[a], tp) : rx.dH) * w;
  }
  // R1 + R2 (char).
  if (cp.charOn && cp.solidC >= 0) {
    const CharGasificationRates cr =
        charGasificationHoisted(cp.charParams, dhChar, tp, pBar, sm[cp.solidC], ref[2 * i]);
    solidRate[cp.solidC] += cr.mdotC;
    for (int g = 0; g < kGasSpeciesCount; ++g)
      if (cp.gasIndex[g] >= 0)
        gasRate[cp.gasIndex[g]] += cr.mdotGas[g];
    heat += cr.heat;
  }
  // R4 + R5 (oxygen carrier).
  if (cp.ocOn && cp.solidFe2O3 >= 0 && cp.solidFe3O4 >= 0 && mi > 0.0) {
    const double mf[3] = {sm[cp.solidFe2O3] / mi, sm[cp.solidFe3O4] / mi, 0.0};
    const int iCO = cp.gasIndex[idx(GasSpecies::CO)], iH2 = cp.gasIndex[idx(GasSpecies::H2)];
    const OcReductionRates orr = ocReductionHoisted(
        cp.ocParams, dhOc, tp, mi, mf, iCO >= 0 ? conc[iCO] : 0.0, iH2 >= 0 ? conc[iH2] : 0.0);
    solidRate[cp.solidFe2O3] += orr.mdotSolid[idx(OcSolid::Fe2O3)];
    solidRate[cp.solidFe3O4] += orr.mdotSolid[idx(OcSolid::Fe3O4)];
    for (int g = 0; g < kGasSpeciesCount; ++g)
      if (cp.gasIndex[g] >= 0)
        gasRate[cp.gasIndex[g]] += orr.mdotGas[g];
    heat += orr.heat;
  }
}

/// Chemistry of the particles and cells: a StepModule (step_module.h) with the ledger
/// ChemistryTotals.
template <class Exec>
class ChemistryModule {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  static constexpr double StageTimes::*kStage = &StageTimes::chemistry;

  void setup(const EngineSetup& s) { setup(s.chem, s.coupled ? s.nCells : 0); }
  void setup(const ChemistrySetup& c, std::size_t nCells) {
    _c = c;
    _c.params.nReactions = static_cast<int>(c.reactions.size());
    auto put = [](auto& arr, const auto& v) {
      arr.allocate(v.size());
      for (std::size_t k = 0; k < v.size(); ++k)
        arr.h()[k] = v[k];
      arr.markHostModified();
      arr.toDevice();
    };
    put(_reactions, c.reactions);
    std::vector<kernels::ReactionEnthalpyPoly> dh;
    for (const kernels::Stoichiometry& st : c.reactionNasa7)
      dh.push_back(st.n > 0 ? kernels::combineReactionEnthalpy(st)
                            : kernels::ReactionEnthalpyPoly{});
    for (kernels::ClgReaction r : {kernels::ClgReaction::R1, kernels::ClgReaction::R2,
                                   kernels::ClgReaction::R4, kernels::ClgReaction::R5})
      dh.push_back(kernels::combineReactionEnthalpy(kernels::clgStoichiometry(r)));
    // All species' breaks together are 850, 960, 1000, 1200 K (5 pieces), so this cannot fire
    // unless species data with more breaks are added (then raise kMaxEnthalpyPieces). No check.h
    // here: this header is compiled by nvcc, which cannot take fmt.
    for (const kernels::ReactionEnthalpyPoly& h : dh)
      if (h.n < 0)
        throw std::logic_error(
            "chemistry: a reaction has more than kMaxEnthalpyPieces enthalpy pieces");
    put(_dh, dh);
    put(_gasM, c.gasMolarMass);
    put(_cp, c.materialCp);
    _width = c.params.nGas + c.params.nSolid + kExtraColumns;
    _acc.allocate((nCells + 1) * static_cast<std::size_t>(_width));
    for (std::size_t k = 0; k < _acc.size(); ++k)
      _acc.h()[k] = 0.0;
    _acc.markHostModified();
    _acc.toDevice();
    _totals.gasProduced.assign(static_cast<std::size_t>(c.params.nGas), 0.0);
    _totals.homogeneousSource.assign(static_cast<std::size_t>(c.params.nGas), 0.0);
    _totals.solidChange.assign(static_cast<std::size_t>(c.params.nSolid), 0.0);
    _totals.removedSolid.assign(static_cast<std::size_t>(c.params.nSolid), 0.0);
  }

  bool enabled() const { return _c.enabled; }

  /// After the sub-step (host): notes a particle below the removal diameter (status array).
  void readStatus(const double* status, const ParticleStore<Exec>&) {
    if (_c.enabled && status[kStatusBelowRemoval] > 0.0)
      _pending = true;
  }

  /// True when a particle fell below the removal diameter since the last call (clears it).
  bool takeRemovalRequest() {
    const bool p = _pending;
    _pending = false;
    return p;
  }

  std::size_t bytes() const {
    return _reactions.bytes() + _dh.bytes() + _gasM.bytes() + _cp.bytes() + _gdot.bytes() +
           _dsolid.bytes() + _q.bytes() + _sens.bytes() + _acc.bytes() + _blockSums.bytes();
  }

  /// Chemistry ledgers since construction (or the restored ones).
  const ChemistryTotals& totals() const { return _totals; }
  /// Continues the ledgers of a state file, or books removed particles (DemSystem).
  void restoreTotals(const ChemistryTotals& t) { _totals = t; }

  void beginWindow(StepContext<Exec>& ctx) {
    if (!_c.enabled)
      return;
    double* acc = _acc.d();
    ctx.exec.parallelFor(_acc.size(), [=] DEM_LAMBDA(std::size_t k) { acc[k] = 0.0; });
    _acc.markDeviceModified();
  }

  /// Steps 1–4 of the file comment. When coupled, the particles are sorted by PCM cell
  /// (ctx.cells) as the drag module leaves them. Reads temperature, material, radius,
  /// mass, density, species, d0, chemRef; writes mass, species, radius, _gdot, _dsolid, _q, _acc.
  void sources(StepContext<Exec>& ctx) {
    if (!_c.enabled)
      return;
    Exec& exec = ctx.exec;
    ParticleStore<Exec>& p = ctx.particles;
    const EngineSetup& s = ctx.setup;
    const double dt = ctx.dt;
    const std::uint32_t* pcell = ctx.cells.pcell();
    const GasFields<Exec>* gasFields = ctx.gas; // nullptr: no gas fields or no coupling grid
    const bool gasPresent = gasFields != nullptr;
    const bool hasRho = gasPresent && gasFields->has(gasFields->rhoG);
    const bool hasY = gasPresent && gasFields->has(gasFields->Yg);
    const bool hasTg = gasPresent && gasFields->has(gasFields->Tg);
    const bool hasCpG = gasPresent && gasFields->has(gasFields->cpG);
    const std::size_t n = p.n;
    const ChemParams cp = _c.params;
    const int nG = cp.nGas, nS = cp.nSolid;
    _gdot.reserve(n * static_cast<std::size_t>(nG > 0 ? nG : 1));
    _dsolid.reserve(n * static_cast<std::size_t>(nS > 0 ? nS : 1));
    _q.reserve(n);
    _sens.reserve(2 * n);
    const bool coupled = s.coupled;
    const bool gas = coupled && gasPresent && hasRho && hasY;
    const bool sensGas = coupled && gasPresent && hasTg && hasCpG;
    const std::uint32_t nCells = static_cast<std::uint32_t>(s.nCells);
    const double* T = p.temperature.d();
    const double* rho = p.density.d();
    const double* d0 = p.d0.d();
    const double* ref = p.chemRef.d();
    double* m = p.mass.d();
    double* X = p.species.d();
    double* r = p.radius.d();
    double* gdot = _gdot.d();
    double* dsol = _dsolid.d();
    double* q = _q.d();
    double* sens = _sens.d();
    const std::int32_t* mat = p.material.d();
    const double* cpm = _cp.d();
    const double* tgC = sensGas ? gasFields->Tg.d() : nullptr;
    const double* cpgC = sensGas ? gasFields->cpG.d() : nullptr;
    const kernels::ReactionEnthalpyPoly* dhPoly = _dh.d();
    // R1/R2 and R4/R5 heats (none when reaction heat is off: the heat is not used then).
    const ChemRateTables tables{_reactions.d(),
                                dhPoly,
                                cp.reactionHeat ? dhPoly + cp.nReactions : nullptr,
                                cp.reactionHeat ? dhPoly + cp.nReactions + 2 : nullptr,
                                _gasM.d(),
                                gas ? gasFields->rhoG.d() : nullptr,
                                gas ? gasFields->Yg.d() : nullptr};

    exec.reduceMaxInto(
        n,
        [=] DEM_LAMBDA(std::size_t i) {
          using namespace kernels;
          const double mi = m[i];
          const double frac = cp.removalFraction;
          double sm[kChemMaxSolids];
          for (int k = 0; k < nS; ++k)
            sm[k] = X[i * nS + k] * mi;
          double solidRate[kChemMaxSolids];
          double gasRate[kChemMaxGas];
          for (int k = 0; k < nS; ++k)
            solidRate[k] = 0.0;
          for (int k = 0; k < nG; ++k)
            gasRate[k] = 0.0;
          double heat = 0.0;
          // A particle holding none of the reactants of any enabled model does nothing (the
          // data-defined reactions check their own solid reactants).
          const bool hasReactant = cp.nReactions > 0 ||
                                   (cp.charOn && cp.solidC >= 0 && sm[cp.solidC] > 0.0) ||
                                   (cp.ocOn && cp.solidFe2O3 >= 0 && sm[cp.solidFe2O3] > 0.0);
          const bool active = hasReactant && !(2.0 * r[i] < frac * d0[i]);
          if (active) {
            // Gas of the particle's PCM cell (no gas: gas-dependent rates are zero).
            const std::uint32_t cell = coupled ? pcell[i] : nCells;
            addParticleReactionRates(cp, tables, gas && cell < nCells, cell, T[i], mi, sm, ref, i,
                                     dt, solidRate, gasRate, heat);
          }
          // One limiter for the particle: no species below zero, no shrinking below half the
          // removal diameter within the step.
          double sc = 1.0;
          double mdot = 0.0;
          for (int k = 0; k < nS; ++k) {
            mdot += solidRate[k];
            const double loss = -solidRate[k] * dt;
            if (loss > sm[k])
              sc = sm[k] > 0.0 ? (sm[k] / loss < sc ? sm[k] / loss : sc) : 0.0;
          }
          if (mdot < 0.0) {
            const double dFloor = 0.5 * frac * d0[i];
            const double mFloor = rho[i] * sphereVolume(0.5 * dFloor);
            const double allowed = mi - mFloor;
            const double loss = -mdot * dt * sc;
            if (!(allowed > 0.0))
              sc = 0.0;
            else if (loss > allowed)
              sc *= allowed / loss;
          }
          // Eq. 31: species masses, total mass, fractions; Eq. 32: radius.
          double mNew = 0.0;
          double mk[kChemMaxSolids];
          for (int k = 0; k < nS; ++k) {
            mk[k] = sm[k] + dt * (sc * solidRate[k]);
            if (mk[k] < 0.0)
              mk[k] = 0.0; // round-off only (the limiter keeps it ≥ 0)
            mNew += mk[k];
          }
          double dmStored = 0.0; // the change of the stored mass (what Σ m c_p T sees)
          if (mNew > 0.0) {      // unchanged particles keep their bits
            bool changed = false;
            for (int k = 0; k < nS; ++k)
              changed = changed || mk[k] != sm[k];
            if (changed) {
              for (int k = 0; k < nS; ++k)
                X[i * nS + k] = mk[k] / mNew;
              m[i] = mNew;
              r[i] = 0.5 * shrinkingDiameter(mNew, rho[i]);
              dmStored = mNew - mi;
            }
          }
          for (int k = 0; k < nS; ++k)
            dsol[i * nS + k] = mk[k] - sm[k];
          double mGas = 0.0; // net gas mass produced by the particle (kg/s)
          for (int k = 0; k < nG; ++k) {
            gdot[i * nG + k] = sc * gasRate[k];
            mGas += gdot[i * nG + k];
          }
          q[i] = cp.reactionHeat ? sc * heat : 0.0;
          // Sensible enthalpy carried by the moved mass (docs/physics.md §3.5): the gas gets ṁ_gas
          // at T_p instead of T_g; the particle's Σ m c_p T changes by Δm c_p T_p without a heat
          // flow.
          const std::uint32_t pc = coupled ? pcell[i] : nCells;
          sens[2 * i] =
              (sensGas && pc < nCells && mGas != 0.0) ? mGas * cpgC[pc] * (T[i] - tgC[pc]) : 0.0;
          sens[2 * i + 1] = dmStored * cpm[mat[i]] * T[i];
          return 2.0 * r[i] < frac * d0[i] ? 1.0 : 0.0;
        },
        0.0, ctx.status + kStatusBelowRemoval);
    p.produced(kMass | kSpecies | kRadius);
    accumulateWindow(ctx);
  }

  /// Step 4: the sub-step's sources added to the window accumulators per cell (+ one row for
  /// particles outside the grid), or, uncoupled, to the window totals. Reads _gdot, _dsolid,
  /// _q, _sens, velocity; writes _acc.
  void accumulateWindow(StepContext<Exec>& ctx) {
    Exec& exec = ctx.exec;
    const EngineSetup& s = ctx.setup;
    const double dt = ctx.dt;
    const std::size_t n = ctx.particles.n;
    const bool coupled = s.coupled;
    const std::uint32_t nCells = static_cast<std::uint32_t>(s.nCells);
    const std::uint32_t* pcell = ctx.cells.pcell();
    const std::uint32_t* perm = ctx.cells.perm();
    const std::uint32_t* cStart = ctx.cells.cStart();
    const std::uint32_t* cEnd = ctx.cells.cEnd();
    const int nG = _c.params.nGas, nS = _c.params.nSolid, W = _width;
    const double* gdot = _gdot.d();
    const double* dsol = _dsolid.d();
    const double* q = _q.d();
    const double* sens = _sens.d();
    const double* vel = ctx.particles.vel.d();
    double* acc = _acc.d();
    const int mom = nG + nS + 3; // first of the three momentum columns
    if (coupled) {
      const std::uint32_t* cs = cStart;
      const std::uint32_t* ce = cEnd;
      exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t h) {
        const std::uint32_t c = pcell[perm[h]];
        if (h > 0 && pcell[perm[h - 1]] == c)
          return;
        // Particles outside the grid share key nCells; their segment starts at the first of them.
        std::uint32_t b = c < nCells ? cs[c] : static_cast<std::uint32_t>(h);
        std::uint32_t e = c < nCells ? ce[c] : static_cast<std::uint32_t>(n);
        const std::size_t row = static_cast<std::size_t>(c < nCells ? c : nCells) * W;
        for (std::uint32_t k = b; k < e; ++k) {
          const std::uint32_t i = perm[k];
          for (int g = 0; g < nG; ++g)
            acc[row + g] += gdot[static_cast<std::size_t>(i) * nG + g] * dt;
          for (int a = 0; a < nS; ++a)
            acc[row + nG + a] += dsol[static_cast<std::size_t>(i) * nS + a];
          acc[row + nG + nS] += q[i] * dt;
          acc[row + nG + nS + 1] += sens[2 * static_cast<std::size_t>(i)] * dt;
          acc[row + nG + nS + 2] += sens[2 * static_cast<std::size_t>(i) + 1];
          // The released gas leaves at the particle's velocity: Σ_k ṁ_k u Δt.
          double mGas = 0.0;
          for (int g = 0; g < nG; ++g)
            mGas += gdot[static_cast<std::size_t>(i) * nG + g];
          if (mGas != 0.0)
            for (int a = 0; a < 3; ++a)
              acc[row + mom + a] += mGas * vel[3 * static_cast<std::size_t>(i) + a] * dt;
        }
      });
    } else {
      // Two levels in a fixed order, so the sums do not depend on the backend or the thread
      // count: per block of kTotalsBlock particles and column, the block's particles in index
      // order; then per column, the blocks in order, added to the window total. n/kTotalsBlock·W
      // threads, then W (the GPU no longer sums all particles in W threads).
      const std::size_t nb = (n + kTotalsBlock - 1) / kTotalsBlock;
      _blockSums.reserve(nb * static_cast<std::size_t>(W));
      double* part = _blockSums.d();
      exec.parallelFor(nb * static_cast<std::size_t>(W), [=] DEM_LAMBDA(std::size_t t) {
        const std::size_t b = t / static_cast<std::size_t>(W);
        const int k = static_cast<int>(t % static_cast<std::size_t>(W));
        const std::size_t lo = b * kTotalsBlock;
        const std::size_t hi = lo + kTotalsBlock < n ? lo + kTotalsBlock : n;
        double sum = 0.0;
        for (std::size_t i = lo; i < hi; ++i) {
          if (k < nG)
            sum += gdot[i * nG + k] * dt;
          else if (k < nG + nS)
            sum += dsol[i * nS + (k - nG)];
          else if (k == nG + nS)
            sum += q[i] * dt;
          else if (k == nG + nS + 1)
            sum += sens[2 * i] * dt;
          else if (k == nG + nS + 2)
            sum += sens[2 * i + 1];
          else { // the momentum of the released gas (column k − mom)
            double mGas = 0.0;
            for (int g = 0; g < nG; ++g)
              mGas += gdot[i * nG + g];
            if (mGas != 0.0)
              sum += mGas * vel[3 * i + static_cast<std::size_t>(k - mom)] * dt;
          }
        }
        part[t] = sum;
      });
      exec.parallelFor(static_cast<std::size_t>(W), [=] DEM_LAMBDA(std::size_t col) {
        double sum = 0.0;
        for (std::size_t b = 0; b < nb; ++b)
          sum += part[b * static_cast<std::size_t>(W) + col];
        acc[col] += sum;
      });
    }
    _acc.markDeviceModified();
  }

  /// After the motion update and the heat module's update: T_i += Δt Q_rxn,i/(m_i c_p,i)
  /// (Eq. 18 with Q_rxn only; the heat module adds the rest).
  void update(StepContext<Exec>& ctx) {
    if (!_c.enabled || !_c.params.reactionHeat)
      return;
    Exec& exec = ctx.exec;
    ParticleStore<Exec>& p = ctx.particles;
    const double dt = ctx.dt;
    const double* q = _q.d();
    const double* m = p.mass.d();
    const std::int32_t* mat = p.material.d();
    const double* cpm = _cp.d();
    double* T = p.temperature.d();
    exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      if (q[i] != 0.0)
        T[i] = T[i] + dt * (q[i] / (m[i] * cpm[mat[i]]));
    });
    p.produced(kTemperature);
  }

  /// Window end (host): R_species from the particle sources, WGS per cell, ledgers.
  /// out.rSpecies / out.qHom are sized (zeros) by the engine.
  /// Coupled runs book its time in stage chemistry.
  void endWindow(WindowContext<Exec>& w) {
    if (!_c.enabled)
      return;
    const auto t0 = std::chrono::steady_clock::now();
    closeWindow(w);
    if (w.setup.coupled)
      w.times.chemistry +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  void closeWindow(WindowContext<Exec>& w) {
    const EngineSetup& s = w.setup;
    CellSources& out = w.out;
    const int nSub = w.nSub;
    _acc.toHost();
    const ChemParams& cp = _c.params;
    const int nG = cp.nGas, nS = cp.nSolid, W = _width;
    const double window = w.dtSub * nSub;
    const std::size_t nc = s.coupled ? s.nCells : 0;
    const double* acc = _acc.h();
    std::vector<double> gasSum(static_cast<std::size_t>(nG), 0.0),
        solidSum(static_cast<std::size_t>(nS), 0.0);
    double heatSum = 0.0, gasSensSum = 0.0, massSensSum = 0.0;
    double momSum[3] = {0.0, 0.0, 0.0};
    const int mom = nG + nS + 3;
    for (std::size_t c = 0; c <= nc; ++c) {
      const double* row = acc + c * W;
      for (int g = 0; g < nG; ++g) {
        gasSum[g] += row[g];
        if (c < nc && window > 0.0)
          out.rSpecies[c * nG + g] += row[g] / (s.cellVolume * window);
      }
      for (int a = 0; a < nS; ++a)
        solidSum[a] += row[nG + a];
      heatSum += row[nG + nS];
      gasSensSum += row[nG + nS + 1];
      massSensSum += row[nG + nS + 2];
      if (c < nc && window > 0.0 && row[nG + nS + 1] != 0.0)
        out.qHom[c] += row[nG + nS + 1] / (s.cellVolume * window);
      for (int a = 0; a < 3; ++a) {
        momSum[a] += row[mom + a];
        if (c < nc && window > 0.0)
          out.momP[3 * c + a] += row[mom + a] / (s.cellVolume * window);
      }
    }
    for (int g = 0; g < nG; ++g)
      _totals.gasProduced[g] += gasSum[g];
    for (int a = 0; a < nS; ++a)
      _totals.solidChange[a] += solidSum[a];
    _totals.reactionHeat += heatSum;
    _totals.gasSensibleHeat += gasSensSum;
    _totals.sensibleMassEnthalpy += massSensSum;
    for (int a = 0; a < 3; ++a)
      _totals.releasedMomentum[a] += momSum[a];

    // R3, homogeneous water–gas shift: once per CFD step per cell from the frozen gas.
    const GasFields<Exec>* gf = w.gas;
    if (cp.wgsOn && nc > 0 && window > 0.0 && gf != nullptr && gf->has(gf->Tg) &&
        gf->has(gf->rhoG) && gf->has(gf->Yg)) {
      const double* tgH = gf->Tg.h();
      const double* rhoH = gf->rhoG.h();
      const double* ygH = gf->Yg.h();
      const double* epsFrozen = w.cells.epsFrozenHost();
      // Per coupling-cell volume: the gas fraction of the cell is φ_f ε_g (ε_g of the fluid).
      const double* fluid = gf->has(gf->fluid) ? gf->fluid.h() : nullptr;
      const double* gasM = _gasM.h();
      std::vector<double> srcSum(static_cast<std::size_t>(nG), 0.0);
      double heat = 0.0;
      for (std::size_t c = 0; c < nc; ++c) {
        // The cell's gas state (the same as the particles' rates use): c_k = ρ_g Y_k/M_k with
        // the case's molar masses.
        double x[kChemMaxGas], conc[kChemMaxGas];
        kernels::cellGasState(rhoH[c], ygH + c * nG, gasM, nG, x, conc);
        double cw[kernels::kGasSpeciesCount];
        for (int g = 0; g < kernels::kGasSpeciesCount; ++g) {
          const int k = cp.gasIndex[g];
          cw[g] = k >= 0 ? conc[k] : 0.0;
        }
        const kernels::WgsCellSources w = kernels::wgsCellSourcesFromConcentrations(
            cp.wgsParams, tgH[c], fluid != nullptr ? fluid[c] * epsFrozen[c] : epsFrozen[c], cw,
            window);
        for (int g = 0; g < kernels::kGasSpeciesCount; ++g) {
          const int k = cp.gasIndex[g];
          if (k < 0)
            continue;
          out.rSpecies[c * nG + k] += w.massSource[g];
          srcSum[k] += w.massSource[g];
        }
        out.qHom[c] += w.heatSource;
        heat += w.heatSource;
      }
      for (int g = 0; g < nG; ++g)
        _totals.homogeneousSource[g] += srcSum[g] * s.cellVolume * window;
      _totals.homogeneousHeat += heat * s.cellVolume * window;
    }
  }

private:
  ChemistrySetup _c;
  Dual<kernels::HeterogeneousReaction> _reactions;
  /// ΔH_r polynomials (combineReactionEnthalpy): one per data-defined reaction (n = 0: constant
  /// dH), then R1, R2, R4, R5 at kClgHeat.
  Dual<kernels::ReactionEnthalpyPoly> _dh;
  Dual<double> _gasM, _cp;
  Dev<double> _gdot;      ///< per particle: gas mass rates (kg/s), N*nGas
  Dev<double> _dsolid;    ///< per particle: solid mass change in this sub-step (kg), N*nSolid
  Dev<double> _q;         ///< per particle: Q_rxn (W)
  Dev<double> _blockSums; ///< uncoupled totals: per block of kTotalsBlock particles and column
  static constexpr std::size_t kTotalsBlock = 256;
  Dev<double> _sens; ///< per particle: ṁ_gas c_p,g (T_p − T_g) (W), Δm c_p T_p (J); N*2
  /// (nCells+1)*W: Σ gas kg, Σ solid kg, Σ Q_rxn J, Σ gas sensible J, Σ Δm c T J, Σ ṁ_gas u Δt
  /// N s (3)
  Dual<double> _acc;
  static constexpr int kExtraColumns = 6; ///< the columns after the gas and solid species
  int _width = 0;                         ///< W = nGas + nSolid + kExtraColumns
  bool _pending = false;                  ///< a particle is below the removal diameter
  ChemistryTotals _totals;
};

} // namespace coredem::dem
