// The DEM server's parts on their own (dem-gpu-server/server/src): the coupling fields' bindings
// to the DEM core's structures, partial-rank combining, session membership and the staggered
// lag. The whole server is tested through its protocol by the other files of this folder.
#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "coredem/common/log.h"
#include "coupling_fields.h"
#include "membership.h"
#include "partial_ranks.h"
#include "staggered_lag.h"

namespace {

namespace proto = coredem::protocol;
namespace f = coredem::protocol::fields;
namespace v1 = coredem::v1;
using namespace coredem::server;

TEST(ServerCouplingFields, EveryTableFieldHasItsOwnMember) {
  // Member pointers compare for equality only: a list searched linearly.
  std::vector<std::span<const double> coredem::dem::GasFieldsView::*> gas;
  for (auto table : {f::gasFields(), f::optionalGasFields()}) {
    for (const auto& spec : table) {
      const auto m = gasFieldMember(spec.name);
      ASSERT_NE(m, nullptr) << spec.name;
      EXPECT_EQ(std::count(gas.begin(), gas.end(), m), 0) << spec.name << " shares a member";
      gas.push_back(m);
    }
  }
  std::vector<std::vector<double> coredem::dem::CellSources::*> sources;
  for (auto table : {f::sourceFields(), f::optionalSourceFields()}) {
    for (const auto& spec : table) {
      const auto m = sourceFieldMember(spec.name);
      ASSERT_NE(m, nullptr) << spec.name;
      EXPECT_EQ(std::count(sources.begin(), sources.end(), m), 0)
          << spec.name << " shares a member";
      sources.push_back(m);
    }
  }
  EXPECT_EQ(gasFieldMember("no_such_field"), nullptr);
  EXPECT_EQ(sourceFieldMember("u_g"), nullptr);
}

/// A whole-grid GasFields of `cells` cells and `species` species; value = 1000·field + index.
proto::Message gasMessage(std::uint64_t cells, std::uint32_t species, bool fluidFraction) {
  auto m = proto::makeGasFields(1, 0.1, 0.1, cells, species);
  double base = 0.0;
  for (const auto& spec : f::gasFields()) {
    base += 1000.0;
    std::vector<double> v(cells * f::componentsOf(spec.extent, species));
    for (std::size_t i = 0; i < v.size(); ++i) {
      v[i] = base + static_cast<double>(i);
    }
    m.addArray<double>(spec.name, std::span<const double>(v),
                       f::shapeOf(spec.extent, cells, species));
  }
  if (fluidFraction) {
    std::vector<double> ff(cells, 0.5);
    m.addArray<double>(f::kFluidFraction, std::span<const double>(ff), {cells});
  }
  return m;
}

TEST(ServerCouplingFields, GasFieldsViewReadsEveryArrayOfTheTable) {
  const auto m = gasMessage(4, 2, false);
  const auto view = gasFieldsView(m);
  EXPECT_EQ(view.ug.data(), m.values<double>(f::kGasVelocity).data());
  EXPECT_EQ(view.gradP.data(), m.values<double>(f::kPressureGradient).data());
  EXPECT_EQ(view.Tg.data(), m.values<double>(f::kGasTemperature).data());
  EXPECT_EQ(view.rhoG.data(), m.values<double>(f::kGasDensity).data());
  EXPECT_EQ(view.muG.data(), m.values<double>(f::kGasViscosity).data());
  EXPECT_EQ(view.kappaG.data(), m.values<double>(f::kGasConductivity).data());
  EXPECT_EQ(view.cpG.data(), m.values<double>(f::kGasHeatCapacity).data());
  EXPECT_EQ(view.Yg.size(), 8u);
  EXPECT_EQ(view.Yg[0], 8000.0);
  EXPECT_TRUE(view.fluidFraction.empty());
  const auto withFraction = gasMessage(4, 2, true);
  EXPECT_EQ(gasFieldsView(withFraction).fluidFraction.size(), 4u);
}

TEST(ServerCouplingFields, SourceValuesFollowTheTable) {
  coredem::dem::CellSources s;
  s.epsG = {0.5};
  s.kSlUs = {1, 2, 3};
  s.qRad = {7};
  EXPECT_EQ(&sourceValues(s, f::kVoidFraction), &s.epsG);
  EXPECT_EQ(&sourceValues(s, f::kDragCoefficientTimesUs), &s.kSlUs);
  EXPECT_EQ(&sourceValues(s, f::kRadiationHeat), &s.qRad);
  EXPECT_THROW((void)sourceValues(s, "u_g"), coredem::InternalError);
}

/// A gas value in its physical range: T_g = `temperature`, the others plausible constants.
double gasValue(std::string_view name, double temperature) {
  if (name == f::kGasTemperature) {
    return temperature;
  }
  if (name == f::kGasViscosity) {
    return 2e-5;
  }
  if (name == f::kGasConductivity) {
    return 0.03;
  }
  if (name == f::kGasHeatCapacity) {
    return 1000.0;
  }
  return 1.0; // u_g, grad_p, rho_g, Y_g (one species)
}

/// A partial GasFields of one rank with the gas at `temperature`: the sums are the values times
/// the rank's fluid volume.
proto::Request partialRequest(const std::vector<std::int64_t>& cells,
                              const std::vector<double>& volume, double temperature) {
  const std::uint64_t m = cells.size();
  proto::Request r;
  r.message = proto::makeGasFields(3, 0.3, 0.1, 2, 1);
  r.message.envelope().mutable_gas_fields()->set_partial(true);
  r.message.envelope().mutable_gas_fields()->set_touched_count(m);
  r.message.addArray<std::int64_t>(f::kTouchedCells, std::span<const std::int64_t>(cells), {m});
  r.message.addArray<double>(f::kFluidVolume, std::span<const double>(volume), {m});
  for (const auto& spec : f::gasFields()) {
    const std::size_t q = f::componentsOf(spec.extent, 1);
    std::vector<double> v(m * q);
    for (std::size_t i = 0; i < m; ++i) {
      for (std::size_t c = 0; c < q; ++c) {
        v[i * q + c] = gasValue(spec.name, temperature) * volume[i];
      }
    }
    r.message.addArray<double>(spec.name, std::span<const double>(v),
                               f::shapeOf(spec.extent, m, 1));
  }
  return r;
}

std::vector<StepReply> repliesOf(const std::vector<proto::Request>& rs) {
  std::vector<StepReply> to;
  for (const auto& r : rs) {
    to.push_back({&r, r.message.values<std::int64_t>(f::kTouchedCells), true});
  }
  return to;
}

TEST(ServerPartialRanks, CombinesVolumeWeightedAndMarksPartlyFluidCells) {
  // Cell 0 is split between the ranks (all fluid), cell 1 is half fluid on rank 1 only.
  std::vector<proto::Request> rs;
  rs.push_back(partialRequest({0}, {0.25}, 300.0));
  rs.push_back(partialRequest({0, 1}, {0.75, 0.5}, 400.0));
  const auto c = combinePartialGasFields(repliesOf(rs), {2, 1}, 1.0, 2);
  ASSERT_TRUE(c.gas.has_value());
  const auto T = c.gas->values<double>(f::kGasTemperature);
  EXPECT_DOUBLE_EQ(T[0], 0.25 * 300.0 + 0.75 * 400.0);
  EXPECT_DOUBLE_EQ(T[1], 400.0);
  const auto ff = c.gas->values<double>(f::kFluidFraction);
  EXPECT_EQ(ff[0], 1.0);
  EXPECT_EQ(ff[1], 0.5);
}

TEST(ServerPartialRanks, RefusesOverlappingVolumes) {
  std::vector<proto::Request> rs;
  rs.push_back(partialRequest({0}, {0.75}, 300.0));
  rs.push_back(partialRequest({0}, {0.75}, 300.0));
  const auto c = combinePartialGasFields(repliesOf(rs), {2, 1}, 1.0, 2);
  ASSERT_FALSE(c.gas.has_value());
  EXPECT_EQ(c.failure.kind, CombineFailure::Kind::Volumes);
  EXPECT_EQ(c.failure.code, v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_NE(c.failure.stepText.find("overlapping decomposition"), std::string::npos);
  EXPECT_EQ(c.failure.rankText, "overlapping fluid volumes");
}

proto::Request hello(v1::Role role, const std::string& peer, std::uint32_t rank,
                     std::uint32_t rankCount, const std::string& session) {
  proto::Request r;
  r.peer = proto::PeerId(peer.begin(), peer.end());
  r.message = proto::makeHello(role, "test " + peer);
  r.message.envelope().mutable_hello()->set_rank(rank);
  r.message.envelope().mutable_hello()->set_rank_count(rankCount);
  r.message.setSessionId(session);
  return r;
}

TEST(ServerMembership, BindsRanksToTheirConnections) {
  Membership m(coredem::logger("dem.server"));
  const proto::Version v = proto::kProtocolVersion;
  EXPECT_EQ(m.admitCfd(hello(v1::ROLE_CFD, "c0", 0, 2, ""), v, "ep")->code,
            v1::ERROR_CODE_NOT_CONFIGURED);
  const auto o = hello(v1::ROLE_ORCHESTRATOR, "o", 0, 0, "");
  ASSERT_FALSE(m.admitOrchestrator(o, v, "ep"));
  EXPECT_EQ(m.state(), coredem::server::SessionState::Connected);
  EXPECT_EQ(m.admitOrchestrator(hello(v1::ROLE_ORCHESTRATOR, "o2", 0, 0, ""), v, "ep")->code,
            v1::ERROR_CODE_SESSION_BUSY);
  const std::string id = m.session();
  EXPECT_EQ(m.admitCfd(hello(v1::ROLE_CFD, "c0", 0, 2, "wrong"), v, "ep")->code,
            v1::ERROR_CODE_UNKNOWN_SESSION);
  EXPECT_EQ(m.admitCfd(hello(v1::ROLE_CFD, "c0", 2, 2, id), v, "ep")->code,
            v1::ERROR_CODE_INVALID_CONFIGURATION);
  const auto c0 = hello(v1::ROLE_CFD, "c0", 0, 2, id);
  ASSERT_FALSE(m.admitCfd(c0, v, "ep"));
  EXPECT_EQ(m.rankCount(), 2u);
  EXPECT_EQ(m.admitCfd(hello(v1::ROLE_CFD, "c1", 1, 3, id), v, "ep")->code,
            v1::ERROR_CODE_INVALID_CONFIGURATION);
  EXPECT_EQ(m.admitCfd(hello(v1::ROLE_CFD, "cx", 0, 2, id), v, "ep")->code,
            v1::ERROR_CODE_SESSION_BUSY);
  ASSERT_FALSE(m.admitCfd(hello(v1::ROLE_CFD, "c1", 1, 2, id), v, "ep"));
  EXPECT_EQ(m.rankOf(c0.peer), 0);
  EXPECT_TRUE(m.isMember(o.peer));
  EXPECT_EQ(m.peerName(c0.peer), "CFD rank 0 of 2 'test c0'");
  EXPECT_EQ(m.cfdName(), "test c0 (2 ranks)");
  m.releaseRank(0);
  m.releaseRankCountIfNoneConnected();
  EXPECT_EQ(m.rankCount(), 2u);
  EXPECT_EQ(m.rankOf(c0.peer), -1);
  m.releaseRank(1);
  m.releaseRankCountIfNoneConnected();
  EXPECT_EQ(m.rankCount(), 0u);
  m.end();
  EXPECT_EQ(m.state(), coredem::server::SessionState::Idle);
  EXPECT_FALSE(m.isMember(o.peer));
  EXPECT_EQ(m.session(), "");
}

TEST(ServerStaggeredLag, RescalesAmountsAndBooksWhatTheGasApplies) {
  StaggeredLag lag;
  StaggeredState s;
  s.speciesComputed = {0.0};
  lag.start(true, s);
  coredem::dem::CellSources computed;
  computed.epsG = {0.5, 0.5};
  computed.heatH = {2.0, 0.0};
  computed.heatHTp = {700.0, 0.0};
  computed.rSpecies = {1.0, 3.0};
  computed.qHom = {4.0, 0.0};
  lag.keep(computed, 0.2);
  ASSERT_TRUE(lag.hasPending());
  std::vector<double> toGas{0.0};
  const std::vector<double> Tg{300.0, 300.0};
  const auto& p = lag.apply(0.1, Tg, 2, 1, 0.5, toGas); // the gas steps half as long
  EXPECT_EQ(p.rSpecies[1], 6.0);
  EXPECT_EQ(p.qHom[0], 8.0);
  EXPECT_EQ(p.epsG[0], 0.5);
  EXPECT_DOUBLE_EQ(toGas[0], (2.0 + 6.0) * 0.5 * 0.1);
  EXPECT_DOUBLE_EQ(lag.state().heatApplied, (700.0 - 600.0) * 0.5 * 0.1);
  lag.markSent();
  EXPECT_FALSE(lag.hasPending());
  lag.reset();
  EXPECT_FALSE(lag.enabled());
}

} // namespace
