// The exchange of a step (docs/client.md): C's GasFields to D, D's Sources back into the
// caller's buffers or viewed in the received frames.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <optional>

#include "coredem/common/check.h"
#include "coredem/protocol/protocol.h"
#include "participant_impl.h"

namespace coredem::client {

using Clock = std::chrono::steady_clock;

const Sources& Participant::Impl::exchange(std::int64_t s, double d,
                                           const std::vector<NamedField>& fields,
                                           const std::vector<NamedBuffer>& into,
                                           const std::vector<std::int64_t>* touched,
                                           ConstView fluidVolume) {
  const auto t0 = Clock::now();
  checkExchangeCall(s, d, touched, fluidVolume);
  // Rows of every array: the grid's cells, or the rank's listed cells.
  const auto cells = touched != nullptr ? static_cast<std::uint64_t>(touched->size())
                                        : static_cast<std::uint64_t>(grid.cellCount());
  auto given = givenGasFields(fields, touched != nullptr);
  if (hasHeatToParticles) { // setHeatToParticles(): Q_split with these fields
    COREDEM_CHECK(given
                      .emplace(std::string(proto::fields::kHeatToParticles),
                               ConstView(heatToParticles.data(), heatToParticles.size()))
                      .second,
                  "exchange: Q_split given both as a field and with setHeatToParticles()");
  }
  const auto dest = sourceBuffers(into, cells);
  auto msg = gasFieldsMessage(given, touched, fluidVolume);
  const auto t1 = Clock::now();
  const auto deadline = t1 + timeout;
  const std::uint64_t seq = dem->send(std::move(msg));
  heatToParticles.clear(); // sent: one exchange only
  hasHeatToParticles = false;
  const auto t2 = Clock::now();
  auto reply = awaitReply(seq, deadline);
  const auto t3 = Clock::now();
  checkSources(reply, touched);
  takeSources(std::move(reply), dest);
  const auto t4 = Clock::now();
  auto sec = [](Clock::duration x) { return std::chrono::duration<double>(x).count(); };
  times = ExchangeTimes{sec(t1 - t0), sec(t2 - t1), sec(t3 - t2), sec(t4 - t3)};
  return sources;
}

std::string Participant::Impl::versionsAgreed() const {
  return fmt::format("the DEM server at {} agreed protocol 1.{}, this "
                     "client speaks {}",
                     demEp, demMinor, proto::kProtocolVersion.toString());
}

void Participant::Impl::checkExchangeCall(std::int64_t s, double d,
                                          const std::vector<std::int64_t>* touched,
                                          ConstView fluidVolume) const {
  COREDEM_CHECK(s == step,
                "exchange(step = {}): the granted step is {}; send the fields of the "
                "granted step",
                s, step);
  COREDEM_CHECK(std::abs(d - dt) <= detail::kDtTolerance * dt,
                "exchange(dt = {:.17g} s): the granted dt of step {} is {:.17g} s; the DEM "
                "sub-cycles exactly the granted dt, so advance by dt()",
                d, step, dt);
  if (touched == nullptr) {
    return;
  }
  const auto gridCells = static_cast<std::uint64_t>(grid.cellCount());
  COREDEM_CHECK(demMinor >= static_cast<int>(proto::kMinorDecomposed),
                "exchangePartial: {}; partial GasFields need 1.{} or later: update coredem-dem",
                versionsAgreed(), proto::kMinorDecomposed);
  COREDEM_CHECK(
      fluidVolume.size == touched->size() && (touched->empty() || fluidVolume.data != nullptr),
      "exchangePartial: {} fluid volumes for {} listed cells", fluidVolume.size, touched->size());
  for (std::size_t i = 0; i < touched->size(); ++i) {
    const std::int64_t g = (*touched)[i];
    COREDEM_CHECK(g >= 0 && static_cast<std::uint64_t>(g) < gridCells &&
                      (i == 0 || g > (*touched)[i - 1]),
                  "exchangePartial: cells[{}] = {}: the list must be strictly ascending "
                  "coupling cells (0..{})",
                  i, g, gridCells - 1);
    COREDEM_CHECK(fluidVolume[i] > 0.0 && std::isfinite(fluidVolume[i]),
                  "exchangePartial: fluid volume {} m3 of cell {} must be positive", fluidVolume[i],
                  g);
  }
}

std::map<std::string, ConstView>
Participant::Impl::givenGasFields(const std::vector<NamedField>& fields, bool partial) const {
  std::map<std::string, ConstView> given;
  for (const auto& f : fields) {
    const auto named = [&](const auto& spec) { return spec.name == f.name; };
    COREDEM_CHECK(proto::fields::findField(f.name) != nullptr &&
                      (std::any_of(proto::fields::gasFields().begin(),
                                   proto::fields::gasFields().end(), named) ||
                       std::any_of(proto::fields::optionalGasFields().begin(),
                                   proto::fields::optionalGasFields().end(), named)),
                  "exchange: '{}' is not a GasFields array; the names are u_g, grad_p, T_g, "
                  "rho_g, mu_g, kappa_g, cp_g, Y_g (and optionally fluid_fraction, Q_split)",
                  f.name);
    COREDEM_CHECK(given.emplace(f.name, f.values).second, "exchange: field '{}' given twice",
                  f.name);
  }
  if (given.count(std::string(proto::fields::kFluidFraction)) != 0) {
    COREDEM_CHECK(!partial,
                  "exchangePartial: fluid_fraction is not sent with partial fields (the DEM "
                  "server forms it from the ranks' fluid volumes)");
    // A 1.1 server would ignore it silently and run the closures without it.
    COREDEM_CHECK(demMinor >= static_cast<int>(proto::kMinorDecomposed),
                  "exchange: {}; fluid_fraction (a mesh that does not fill the coupling grid) "
                  "needs 1.{} or later: update coredem-dem",
                  versionsAgreed(), proto::kMinorDecomposed);
  }
  if (given.count(std::string(proto::fields::kHeatToParticles)) != 0) {
    // An older server would ignore it and the heat would be lost.
    COREDEM_CHECK(demMinor >= static_cast<int>(proto::kMinorHeatToParticles),
                  "exchange: {}; Q_split (heat for the particles) needs 1.{} or later: update "
                  "coredem-dem",
                  versionsAgreed(), proto::kMinorHeatToParticles);
  }
  return given;
}

std::map<std::string, const NamedBuffer*>
Participant::Impl::sourceBuffers(const std::vector<NamedBuffer>& into, std::uint64_t cells) const {
  const auto ns = static_cast<std::uint64_t>(grid.species.size());
  std::map<std::string, const NamedBuffer*> dest;
  for (const auto& b : into) {
    const auto* spec = proto::fields::findField(b.name);
    const auto named = [&](const auto& sp) { return sp.name == b.name; };
    COREDEM_CHECK(spec != nullptr &&
                      (std::any_of(proto::fields::sourceFields().begin(),
                                   proto::fields::sourceFields().end(), named) ||
                       std::any_of(proto::fields::optionalSourceFields().begin(),
                                   proto::fields::optionalSourceFields().end(), named)),
                  "exchange: '{}' is not a Sources array; the names are eps_g, K_sl, K_sl_Us, H, "
                  "H_Tp, R_species, Q_hom, Q_rad, mom_p",
                  b.name);
    const std::uint64_t n = cells * proto::fields::componentsOf(spec->extent, ns);
    COREDEM_CHECK(b.size == n,
                  "exchange: the buffer for '{}' holds {} values; the coupling grid "
                  "has {} cells, so it needs {} ({} per cell)",
                  b.name, b.size, cells, n, proto::fields::componentsOf(spec->extent, ns));
    COREDEM_CHECK(n == 0 || b.data != nullptr, "exchange: buffer for '{}' points to null", b.name);
    COREDEM_CHECK(dest.emplace(b.name, &b).second, "exchange: buffer for '{}' given twice", b.name);
  }
  return dest;
}

proto::Message Participant::Impl::gasFieldsMessage(const std::map<std::string, ConstView>& given,
                                                   const std::vector<std::int64_t>* touched,
                                                   ConstView fluidVolume) const {
  const auto gridCells = static_cast<std::uint64_t>(grid.cellCount());
  const auto cells = touched != nullptr ? static_cast<std::uint64_t>(touched->size()) : gridCells;
  const auto ns = static_cast<std::uint64_t>(grid.species.size());
  auto msg = proto::makeGasFields(step, time, dt, gridCells, static_cast<std::uint32_t>(ns));
  msg.setSessionId(session);
  if (touched != nullptr) {
    msg.envelope().mutable_gas_fields()->set_partial(true);
    msg.envelope().mutable_gas_fields()->set_touched_count(cells);
    msg.addArray<std::int64_t>(proto::fields::kTouchedCells,
                               std::span<const std::int64_t>(*touched), {cells});
    msg.addArray<double>(proto::fields::kFluidVolume,
                         std::span<const double>(fluidVolume.data, fluidVolume.size), {cells});
  }
  for (const auto& spec : proto::fields::gasFields()) {
    const std::string name(spec.name);
    const auto it = given.find(name);
    COREDEM_CHECK(it != given.end(), "exchange: the gas field '{}' ({}) is missing", name,
                  spec.unit);
    const auto shape = proto::fields::shapeOf(spec.extent, cells, ns);
    const std::uint64_t n = cells * proto::fields::componentsOf(spec.extent, ns);
    COREDEM_CHECK(it->second.size == n,
                  "exchange: '{}' has {} values; the coupling grid has {} cells, so it needs {} "
                  "({} per cell)",
                  name, it->second.size, cells, n, proto::fields::componentsOf(spec.extent, ns));
    COREDEM_CHECK(n == 0 || it->second.data != nullptr, "exchange: '{}' points to null", name);
    // One copy into the message: zero-copy would leave ZeroMQ pointing into the caller's
    // arrays after a timed-out request, when the caller may already have freed them.
    msg.addArray<double>(name, std::span<const double>(it->second.data, it->second.size), shape);
  }
  for (const auto& spec : proto::fields::optionalGasFields()) {
    const std::string name(spec.name);
    const auto it = given.find(name);
    if (it == given.end()) {
      continue;
    }
    const std::uint64_t n = cells * proto::fields::componentsOf(spec.extent, ns);
    COREDEM_CHECK(it->second.size == n && (n == 0 || it->second.data != nullptr),
                  "exchange: '{}' has {} values; the coupling grid (or the rank's list) has {} "
                  "cells, so it needs {}",
                  name, it->second.size, cells, n);
    msg.addArray<double>(name, std::span<const double>(it->second.data, it->second.size),
                         proto::fields::shapeOf(spec.extent, cells, ns));
  }
  return msg;
}

proto::Message Participant::Impl::awaitReply(std::uint64_t seq, Clock::time_point deadline) {
  const std::string what = "Sources for step " + std::to_string(step);
  // The reply's frames are kept (no copy): the arrays are viewed in place, or copied once
  // into the caller's buffers. Replies to earlier, timed-out requests are skipped.
  std::optional<proto::Message> reply;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() > 0) {
      reply = dem->receive(left);
    }
    if (!reply) {
      throw proto::TimeoutError(demEp, what,
                                fmt::format("no reply from DEM server {} within {} ms while "
                                            "awaiting the {}; is it running, reachable and not "
                                            "stalled?",
                                            demEp, timeout.count(), what));
    }
    const auto& env = reply->envelope();
    if (env.sequence() == seq || (env.sequence() == 0 && reply->type() == v1::MESSAGE_TYPE_ERROR)) {
      break;
    }
    log->debug("{}: discarding a stale reply (sequence {}) while awaiting {}", opt.name,
               env.sequence(), seq);
    reply.reset();
  }
  return std::move(*reply);
}

void Participant::Impl::checkSources(const proto::Message& reply,
                                     const std::vector<std::int64_t>* touched) const {
  proto::expectType(reply, v1::MESSAGE_TYPE_SOURCES);
  proto::Expectation e;
  e.types = {v1::MESSAGE_TYPE_SOURCES};
  e.step = step;
  e.cells = static_cast<std::uint64_t>(grid.cellCount());
  e.species = static_cast<std::uint64_t>(grid.species.size());
  if (const auto st = proto::validate(reply, e); !st.ok()) {
    throw proto::ProtocolError(st.code, "DEM server " + demEp + " sent bad Sources for step " +
                                            std::to_string(step) + ": " + st.message);
  }
  // A partial GasFields is answered with the sources of the same cells, in the same order.
  const bool partialReply = reply.envelope().sources().partial();
  bool sameCells = partialReply == (touched != nullptr);
  if (sameCells && touched != nullptr) {
    const auto back = reply.findArray(proto::fields::kTouchedCells)->as<std::int64_t>();
    sameCells = std::equal(back.begin(), back.end(), touched->begin(), touched->end());
  }
  if (!sameCells) {
    throw proto::ProtocolError(v1::ERROR_CODE_SHAPE,
                               fmt::format("DEM server {} answered the {} GasFields of step {} "
                                           "with Sources of {}",
                                           demEp, touched != nullptr ? "partial" : "whole-grid",
                                           step, partialReply ? "other cells" : "the whole grid"));
  }
}

void Participant::Impl::takeSources(proto::Message reply,
                                    const std::map<std::string, const NamedBuffer*>& dest) {
  auto kept = std::make_shared<proto::Message>(std::move(reply));
  Sources next;
  std::vector<std::pair<const NamedBuffer*, std::span<const double>>> copies;
  std::vector<const NamedBuffer*> zeroed; // buffers of optional arrays D did not send
  std::vector<proto::fields::FieldSpec> received(proto::fields::sourceFields().begin(),
                                                 proto::fields::sourceFields().end());
  received.insert(received.end(), proto::fields::optionalSourceFields().begin(),
                  proto::fields::optionalSourceFields().end());
  for (const auto& spec : received) {
    const std::string name(spec.name);
    if (!kept->findArray(name)) {
      if (const auto b = dest.find(name); b != dest.end()) {
        zeroed.push_back(b->second);
      }
      continue;
    }
    const auto v = kept->values<double>(name);
    if (const auto b = dest.find(name); b != dest.end()) {
      if (b->second->size != v.size()) {
        throw proto::ProtocolError(v1::ERROR_CODE_SHAPE,
                                   fmt::format("DEM server {} sent {} values of '{}' for step {}; "
                                               "the buffer given for it holds {}",
                                               demEp, v.size(), name, step, b->second->size));
      }
      copies.emplace_back(b->second, v);
    } else {
      next.views[name] = ConstView(v.data(), v.size());
    }
  }
  for (const auto& [b, v] : copies) { // only after every size was checked
    if (!v.empty()) {
      std::memcpy(b->data, v.data(), v.size() * sizeof(double));
    }
    next.views[b->name] = ConstView(b->data, b->size);
  }
  for (const NamedBuffer* b : zeroed) {
    std::fill(b->data, b->data + b->size, 0.0);
  }
  next.step = step;
  next.substeps = kept->envelope().sources().substeps();
  next.storage = std::move(kept);
  sources = std::move(next);
  state = State::Exchanged;
}

} // namespace coredem::client
