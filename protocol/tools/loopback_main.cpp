// coredem-loopback: the protocol loopback server and a one-step exchange client.
//   coredem-loopback serve    [--endpoint tcp://127.0.0.1:*] [--endpoint-file F] [--idle-limit S]
//                             [--protocol-minor M]  (speak 1.M, e.g. 0 to act as a v1.0 peer)
//   coredem-loopback exchange --endpoint E [--grid NX NY NZ] [--species N] [--steps K]
//                             [--timeout S] [--shutdown]
// `serve` prints the bound endpoint (and writes it to --endpoint-file) and serves until a
// Shutdown arrives. `exchange` does Hello, Configure, K x GasFields->Sources, checks the
// loopback's checksums and prints what was sent, how many bytes and how long it took.
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <numeric>

#include <CLI/CLI.hpp>

#include <coredem/common/log.h>
#include <coredem/protocol/fields.h>
#include <coredem/protocol/loopback.h>
#include <coredem/protocol/validate.h>

using namespace coredem::protocol;
using namespace coredem;
using Clock = std::chrono::steady_clock;

namespace {

std::atomic<bool> gStop{false};
void onSignal(int) {
  gStop = true;
}

int serve(const std::string& endpoint, const std::string& endpointFile, double idleLimit,
          int minor) {
  TransportOptions options;
  options.sender = "coredem-loopback";
  LoopbackService service(options, minor < 0
                                       ? kProtocolVersion
                                       : Version{kProtocolVersion.major, std::uint32_t(minor)});
  std::string bound = service.bind(endpoint);
  if (!endpointFile.empty()) {
    // Write to a temporary name and rename, so a reader never sees a partial endpoint.
    std::string tmp = endpointFile + ".tmp";
    {
      std::ofstream out(tmp);
      out << bound << "\n";
    }
    std::rename(tmp.c_str(), endpointFile.c_str());
  }
  std::printf("coredem-loopback: serving on %s\n", bound.c_str());
  std::fflush(stdout);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  auto n = service.serve(&gStop, std::chrono::milliseconds(static_cast<long>(idleLimit * 1000)));
  std::printf("coredem-loopback: served %llu requests (%llu refused), stopping\n",
              static_cast<unsigned long long>(n),
              static_cast<unsigned long long>(service.errorsSent()));
  return 0;
}

/// A smooth, deterministic field value (so the checksum test is not trivially zero).
double fieldValue(std::size_t fieldIndex, std::size_t i) {
  return 1.0 + 0.5 * static_cast<double>(fieldIndex) + 1e-6 * static_cast<double>(i % 1000);
}

int exchange(const std::string& endpoint, std::vector<std::uint64_t> grid, std::uint32_t nSpecies,
             int steps, double timeoutSeconds, bool shutdown) {
  const auto timeout = std::chrono::milliseconds(static_cast<long>(timeoutSeconds * 1000));
  TransportOptions options;
  options.sender = "coredem-loopback exchange";
  Client client(options);
  client.connect(endpoint);

  auto t0 = Clock::now();
  Message welcome = client.request(makeHello(v1::ROLE_TOOL, "coredem-loopback 1.0"), timeout);
  expectType(welcome, v1::MESSAGE_TYPE_WELCOME);
  const std::string session = welcome.envelope().welcome().session_id();
  std::printf("handshake: protocol %u.%u, session %s (%.1f ms)\n",
              welcome.envelope().welcome().protocol_major(),
              welcome.envelope().welcome().protocol_minor(), session.c_str(),
              std::chrono::duration<double, std::milli>(Clock::now() - t0).count());

  const std::uint64_t cells = grid[0] * grid[1] * grid[2];
  v1::Configure cfg;
  cfg.set_case_name("loopback");
  auto* g = cfg.mutable_coupling_mesh()->mutable_cartesian();
  g->mutable_spacing()->set_x(0.002);
  g->mutable_spacing()->set_y(0.002);
  g->mutable_spacing()->set_z(0.002);
  g->mutable_counts()->set_x(grid[0]);
  g->mutable_counts()->set_y(grid[1]);
  g->mutable_counts()->set_z(grid[2]);
  const char* names[] = {"O2", "N2", "CO2", "H2O", "CO", "H2", "CH4", "Ar"};
  const double molar[] = {0.032, 0.028, 0.044, 0.018, 0.028, 0.002, 0.016, 0.040};
  for (std::uint32_t k = 0; k < nSpecies; ++k) {
    auto* s = cfg.add_species();
    s->set_name(k < 8 ? names[k] : "S" + std::to_string(k));
    s->set_molar_mass(k < 8 ? molar[k] : 0.03);
  }
  cfg.mutable_sub_cycling()->set_dt_cfd(1e-4);
  cfg.mutable_sub_cycling()->set_n_sub(50);
  cfg.mutable_sub_cycling()->set_dt_dem(1e-4 / 50);
  Message configured = client.request(std::move(makeConfigure(cfg).setSessionId(session)), timeout);
  expectType(configured, v1::MESSAGE_TYPE_CONFIGURED);
  std::printf("configure: %llu x %llu x %llu = %llu cells, %u species\n",
              static_cast<unsigned long long>(grid[0]), static_cast<unsigned long long>(grid[1]),
              static_cast<unsigned long long>(grid[2]), static_cast<unsigned long long>(cells),
              nSpecies);

  // GasFields arrays, built once.
  std::vector<std::shared_ptr<std::vector<double>>> data;
  std::vector<double> expectedChecksum;
  std::size_t fi = 0;
  for (const auto& f : fields::gasFields()) {
    std::size_t n = cells * fields::componentsOf(f.extent, nSpecies);
    auto v = std::make_shared<std::vector<double>>(n);
    for (std::size_t i = 0; i < n; ++i) {
      (*v)[i] = fieldValue(fi, i);
    }
    expectedChecksum.push_back(std::accumulate(v->begin(), v->end(), 0.0));
    data.push_back(v);
    ++fi;
  }

  int failures = 0;
  for (int step = 0; step < steps; ++step) {
    Message gas = makeGasFields(step, step * 1e-4, 1e-4, cells, nSpecies);
    gas.setSessionId(session);
    fi = 0;
    for (const auto& f : fields::gasFields()) {
      gas.addArrayShared<double>(f.name, data[fi], std::span<const double>(*data[fi]),
                                 fields::shapeOf(f.extent, cells, nSpecies));
      ++fi;
    }
    if (step == 0) {
      std::printf("GasFields arrays sent (float64, little-endian):\n");
      for (std::size_t i = 0; i < gas.arrayCount(); ++i) {
        auto v = gas.array(i);
        std::string shape;
        for (auto d : v.shape()) {
          if (!shape.empty()) {
            shape += ',';
          }
          shape += std::to_string(d);
        }
        std::printf("  %-8s [%s]  %llu bytes\n", v.name().c_str(), shape.c_str(),
                    static_cast<unsigned long long>(v.bytes.size()));
      }
    }
    const auto sentBytes = gas.payloadBytes();
    auto t1 = Clock::now();
    Message src = client.request(std::move(gas), timeout);
    double seconds = std::chrono::duration<double>(Clock::now() - t1).count();
    expectType(src, v1::MESSAGE_TYPE_SOURCES);
    Expectation e;
    e.types = {v1::MESSAGE_TYPE_SOURCES};
    e.cells = cells;
    e.species = nSpecies;
    e.step = step;
    if (Status s = validate(src, e); !s.ok()) {
      std::fprintf(stderr, "invalid Sources reply: %s\n", s.toString().c_str());
      return 1;
    }
    auto checksum = src.values<double>("checksum");
    for (std::size_t i = 0; i < expectedChecksum.size(); ++i) {
      // Both sides sum the same values in the same order: the sums agree exactly.
      if (checksum[i] != expectedChecksum[i]) {
        std::fprintf(stderr, "checksum mismatch for %s: sent %.17g, server saw %.17g\n",
                     std::string(fields::gasFields()[i].name).c_str(), expectedChecksum[i],
                     checksum[i]);
        ++failures;
      }
    }
    const auto recvBytes = src.payloadBytes();
    std::printf("step %d: sent %llu bytes (%zu arrays), received %llu bytes (%zu arrays) in "
                "%.1f ms round trip = %.2f GB/s; checksums %s\n",
                step, static_cast<unsigned long long>(sentBytes), fields::gasFields().size(),
                static_cast<unsigned long long>(recvBytes), src.arrayCount(), seconds * 1e3,
                static_cast<double>(sentBytes + recvBytes) / seconds / 1e9,
                failures ? "MISMATCH" : "match");
  }
  if (shutdown) {
    Message ack =
        client.request(std::move(makeShutdown("exchange finished").setSessionId(session)), timeout);
    expectType(ack, v1::MESSAGE_TYPE_ACK);
    std::printf("shutdown acknowledged\n");
  }
  return failures ? 1 : 0;
}

} // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0); // keep lines in order with the server's output
  CLI::App app{"CoReDEM protocol loopback server and exchange client"};
  app.require_subcommand(1);
  std::string endpoint = "tcp://127.0.0.1:*";
  std::string endpointFile;
  double idleLimit = 0;
  auto* serveCmd = app.add_subcommand("serve", "run the loopback server until Shutdown");
  serveCmd->add_option("--endpoint", endpoint, "endpoint to bind (loopback or ipc)");
  serveCmd->add_option("--endpoint-file", endpointFile, "write the bound endpoint here");
  serveCmd->add_option("--idle-limit", idleLimit,
                       "stop after this many seconds without requests (0 = never)");
  int minor = -1;
  serveCmd->add_option("--protocol-minor", minor, "speak protocol 1.MINOR (default: this build's)");

  std::string target;
  std::vector<std::uint64_t> grid{100, 400, 10};
  std::uint32_t species = 4;
  int steps = 1;
  double timeout = 60;
  bool shutdown = false;
  auto* exCmd = app.add_subcommand("exchange", "handshake, configure and exchange coupling steps");
  exCmd->add_option("--endpoint", target, "server endpoint")->required();
  exCmd->add_option("--grid", grid, "cells per axis NX NY NZ")->expected(3);
  exCmd->add_option("--species", species, "number of gas species");
  exCmd->add_option("--steps", steps, "coupling steps to exchange");
  exCmd->add_option("--timeout", timeout, "seconds to wait for each reply");
  exCmd->add_flag("--shutdown", shutdown, "send Shutdown to the server at the end");
  CLI11_PARSE(app, argc, argv);
  try {
    if (*serveCmd) {
      return serve(endpoint, endpointFile, idleLimit, minor);
    }
    return exchange(target, grid, species, steps, timeout, shutdown);
  } catch (const coredem::UserError& e) {
    std::fprintf(stderr, "coredem-loopback: %s\n", e.what());
    return 1;
  }
}
