#pragma once
/// @file
/// The coupling client: the only thing a CFD solver links to take part in a CoReDEM run
/// (docs/client.md). One class behind pimpl; no ZeroMQ, protobuf or OpenFOAM type appears
/// here, and this header compiles as C++14 (OpenFOAM translation units use C++14).
///
/// @code
///   coredem::client::Participant p;            // endpoints from COREDEM_* environment variables
///   p.initialize();                            // handshakes with O and D, first grant
///   while (p.isRunning()) {
///     ... advance the CFD solution by p.dt() ...
///     const coredem::client::Sources& s = p.exchange(p.step(), p.dt(), {
///         {"u_g", {u.data(), u.size()}}, {"grad_p", gradP}, {"T_g", T}, {"rho_g", rho},
///         {"mu_g", mu}, {"kappa_g", kappa}, {"cp_g", cp}, {"Y_g", Y}});
///     applySources(s.field("eps_g"), s.field("K_sl"), ...);
///     p.advance(courant, ledgers, checkpointFiles);   // StepDone -> next grant or Shutdown
///   }
///   p.finalize();
/// @endcode
///
/// Every call checks the participant's state first and throws StateError when called out of
/// order; bad arguments throw ClientError(Argument); a peer that does not answer within the
/// deadline throws ClientError(Timeout) naming the peer and the awaited reply.

#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace coredem {
namespace client {

/// Read-only view of contiguous doubles (a C++14 stand-in for std::span<const double>).
struct ConstView {
  const double* data = nullptr;
  std::size_t size = 0;

  ConstView() = default;
  ConstView(const double* d, std::size_t n)
      : data(d)
      , size(n) {}
  /// Any contiguous container of doubles (std::vector, std::array, std::span, Foam::List...).
  template <class Container,
            class = decltype(static_cast<const double*>(std::declval<const Container&>().data())),
            class = decltype(static_cast<std::size_t>(std::declval<const Container&>().size()))>
  ConstView(const Container& c)
      : data(c.data())
      , size(static_cast<std::size_t>(c.size())) {}

  const double* begin() const { return data; }
  const double* end() const { return data + size; }
  double operator[](std::size_t i) const { return data[i]; }
};

/// One named array passed to exchange(): a GasFields name of docs/protocol.md and its values.
struct NamedField {
  std::string name;
  ConstView values;
};

/// A caller-owned destination for one Sources array (exchange(..., into)): the array is copied
/// from the received frame straight into data[0, size) (size must equal the array's length),
/// e.g. a solver's own field storage or a pinned buffer.
struct NamedBuffer {
  std::string name;
  double* data = nullptr;
  std::size_t size = 0;
};

/// Wall-clock split of the last exchange() in seconds (coredemFoam -timers).
struct ExchangeTimes {
  double serialise = 0.0; ///< argument checks + copying the gas arrays into the message
  double send = 0.0;      ///< handing the message to the transport
  double wait = 0.0;      ///< from sent until D's reply was received (D's work + transfer)
  double receive = 0.0;   ///< validating the reply, copies into NamedBuffers, views
};

/// What went wrong, for callers that branch on it (and for the C API's status codes).
enum class ErrorCode {
  Argument = 1, ///< a bad argument or environment (missing endpoint, wrong field size, ...)
  State = 2,    ///< a call out of order (see State)
  Protocol = 3, ///< a malformed or unexpected message from a peer
  Timeout = 4,  ///< a peer did not answer within the deadline
  Peer = 5,     ///< a peer answered with Error or Reject (message has its code and text)
  Internal = 6  ///< a bug in CoReDEM
};

/// Every error thrown by the client library.
class ClientError : public std::runtime_error {
public:
  ClientError(ErrorCode code, const std::string& message)
      : std::runtime_error(message)
      , _code(code) {}
  ErrorCode code() const { return _code; }

private:
  ErrorCode _code;
};

/// A call was made in a state that does not allow it.
class StateError : public ClientError {
public:
  explicit StateError(const std::string& message)
      : ClientError(ErrorCode::State, message) {}
};

/// The participant's life cycle. Allowed calls:
/// Created --initialize--> Granted (or Finished when O shut the run down at once)
/// Granted --exchange--> Exchanged --advance--> Granted | Finished
/// any --finalize--> Finalized
enum class State { Created, Granted, Exchanged, Finished, Finalized };

/// "Created", "Granted", ...
const char* stateName(State s);

/// How to reach the orchestrator (O) and the DEM server (D). Empty strings are taken from the
/// environment: COREDEM_CONTROL_ENDPOINT, COREDEM_DEM_ENDPOINT, COREDEM_SESSION,
/// COREDEM_TIMEOUT_S (docs/client.md).
struct Options {
  std::string controlEndpoint;
  std::string demEndpoint;
  std::string sessionId;
  double timeoutSeconds = 0.0; ///< per-request deadline; 0 = environment or 60 s
  std::string name = "cfd";    ///< this participant's name in logs and messages
  std::string softwareVersion; ///< e.g. "coredemFoam 0.1.0"; empty = the library's version
  /// CURVE keys (Z85) when D requires them (remote D): D's public key. Environment:
  /// COREDEM_DEM_SERVER_KEY.
  std::string demServerPublicKey;
  /// With demServerPublicKey: this client's persistent key pair, for a D with an allow-list
  /// (`coredem-dem --client-keys`): the path of `client.secret` (or of the folder holding
  /// it) written by `coredem-dem --generate-client-key DIR`; a path, never the key itself.
  /// Empty: a throw-away pair is generated (enough for a D without an allow-list).
  /// Environment: COREDEM_DEM_CLIENT_KEY_FILE.
  std::string demClientKeyFile;
  /// Decomposed CFD (protocol 1.2, docs/client.md "Decomposed runs"): this process's rank index
  /// (0-based) and the number of ranks. rankCount <= 1: not decomposed. Rank 0 talks to the
  /// orchestrator (initialize(), advance()) and hands its controlState() to the other ranks,
  /// which call follow() instead; every rank exchanges its own partial fields with D
  /// (exchangePartial()).
  int rank = 0;
  int rankCount = 0;
};

/// The coupling grid and species from O's Configure.
struct Grid {
  double origin[3] = {0.0, 0.0, 0.0};  ///< m, lower corner of cell (0,0,0)
  double spacing[3] = {0.0, 0.0, 0.0}; ///< m
  std::int64_t counts[3] = {0, 0, 0};  ///< cells per axis; cell = i + nx*(j + ny*k)
  std::vector<std::string> species;    ///< gas species, the column order of Y_g / R_species
  std::vector<double> molarMasses;     ///< kg/mol, same order
  std::int64_t cellCount() const { return counts[0] * counts[1] * counts[2]; }
};

/// Sources of the last exchange (sub-step averages over the CFD step), valid until the next
/// exchange() or finalize(). Names: eps_g, K_sl, K_sl_Us, H, H_Tp, R_species, Q_hom, with a
/// DEM server of protocol 1.3 or later Q_rad (radiationHeat()) and of 1.5 or later mom_p
/// (releasedMomentum()).
/// Arrays are not copied on receipt: field() views the received frames (kept alive by
/// `storage`), or the caller's NamedBuffer the array was received into.
class Sources {
public:
  /// The named array; throws ClientError(Argument) for a name D did not send.
  ConstView field(const std::string& name) const;
  /// Q_rad: the net radiation heat the particles of each cell gave the gas, W per m3 of coupling
  /// cell, sub-step averaged like H and H_Tp (positive = heat to the gas; one value per cell, or
  /// per listed cell after exchangePartial()). Add it to the gas energy equation as an explicit
  /// source. Empty (size 0) when the DEM server did not send it (agreed protocol below 1.3: the
  /// radiation heat then leaves the system, as before 1.3).
  ConstView radiationHeat() const;
  /// mom_p: the momentum of the mass the particles of each cell give the gas, N per m3 of
  /// coupling cell (sum of released mass rate times particle velocity / V_c, sub-step averaged
  /// like R_species; 3 values per cell, x y z, or per listed cell after exchangePartial()). The gas
  /// adds mom_p - S_m U to its momentum equation (S_m = sum of R_species): the released mass then
  /// carries the particles' momentum instead of entering at the gas velocity. Empty (size 0) when
  /// the DEM server did not send it (agreed protocol below 1.5).
  ConstView releasedMomentum() const;
  bool has(const std::string& name) const;
  std::vector<std::string> names() const;
  std::int64_t step = 0;
  std::uint32_t substeps = 0;                        ///< DEM sub-steps averaged
  std::map<std::string, ConstView> views;            ///< every array D sent, by name
  std::map<std::string, std::vector<double>> arrays; ///< arrays that had to be converted
  std::shared_ptr<const void> storage;               ///< owns the frames `views` point into
};

/// Ledgers reported in StepDone (named doubles, docs/client.md).
struct Ledgers {
  std::vector<std::pair<std::string, double>> mass;    ///< kg
  std::vector<std::pair<std::string, double>> energy;  ///< J
  std::vector<std::pair<std::string, double>> species; ///< kg
  /// Other figures for O's time series (StepDone.diagnostics), e.g. ("gas.solid_volume_m3", v).
  std::vector<std::pair<std::string, double>> diagnostics;
};

class Participant {
public:
  explicit Participant(Options options = Options());
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;
  Participant(Participant&&) noexcept;
  Participant& operator=(Participant&&) noexcept;

  /// Handshakes with O (Hello, Configure), connects to D (Hello), tells O it is ready and
  /// waits for the first grant.
  /// @pre state() == Created  @post state() == Granted, or Finished if O ended the run
  void initialize();

  State state() const;
  /// True while O keeps granting steps (state Granted or Exchanged).
  bool isRunning() const;

  // ---- the current grant (valid in Granted / Exchanged) ---------------------------------
  std::int64_t step() const;         ///< step number n of the grant
  double time() const;               ///< s, simulated time at the start of step n
  double dt() const;                 ///< s, Δt_CFD of step n: advance exactly this much
  int nSub() const;                  ///< DEM sub-steps of the step
  double dtDem() const;              ///< s, Δt_DEM = dt()/nSub()
  bool requiresCheckpoint() const;   ///< write your state after this step
  std::string checkpointDir() const; ///< where to write it ("" if not requested)
  /// Write your output fields (for users: the gas at this instant) after this step: the
  /// orchestrator writes the particle snapshot of the same step (`output` in case.yaml).
  bool requiresOutput() const;
  /// Why O ended the run (valid in Finished).
  std::string shutdownReason() const;

  /// Coupling grid and species (valid after initialize).
  const Grid& grid() const;
  /// Start step and time from Configure (e.g. a restart).
  std::int64_t startStep() const;
  double startTime() const;

  /// Sends the gas fields of step `step` to D and returns D's sources.
  /// Required names: u_g [N*3], grad_p [N*3], T_g, rho_g, mu_g, kappa_g, cp_g [N],
  /// Y_g [N*n_species]; sizes are checked here before anything is sent.
  /// @pre state() == Granted, step == this->step(), dt == this->dt() (relative 1e-12)
  /// @post state() == Exchanged
  const Sources& exchange(std::int64_t step, double dt, const std::vector<NamedField>& fields);
  /// As above; the Sources arrays named in `into` are received straight into those buffers
  /// (one copy from the received frame, none in between) and field() views them there.
  /// A name that is not a Sources array or a size other than cells x components throws
  /// ClientError(Argument) before anything is sent; buffers are written only after D's reply
  /// passed validation. A buffer for Q_rad that D did not send (protocol below 1.3) is set to
  /// zeros and radiationHeat() stays empty.
  const Sources& exchange(std::int64_t step, double dt, const std::vector<NamedField>& fields,
                          const std::vector<NamedBuffer>& into);

  /// Decomposed runs: sends this rank's partial GasFields and returns the Sources of its cells.
  /// `cells` lists the coupling cells this rank's mesh cells overlap (strictly ascending, each
  /// < grid().cellCount(); may be empty), `fluidVolume` this rank's fluid volume in each (m3,
  /// > 0), and every gas field of exchange() is given as volume-weighted sums over the rank's
  /// cells, cells.size() rows. The returned arrays have cells.size() rows in the same order
  /// (per coupling-cell volume, as in exchange()). fluid_fraction is not sent (D forms it).
  /// Needs a DEM server of protocol 1.2 or later. @pre/@post as exchange()
  const Sources& exchangePartial(std::int64_t step, double dt,
                                 const std::vector<std::int64_t>& cells, ConstView fluidVolume,
                                 const std::vector<NamedField>& sums);

  /// Decomposed runs, rank 0: the state the other ranks follow (grid, species, start, the
  /// current grant or the end of the run) as an opaque string to broadcast (e.g. with MPI).
  /// @pre initialize() or advance() returned
  std::string controlState() const;
  /// Decomposed runs, ranks > 0: take rank 0's controlState() instead of talking to the
  /// orchestrator. The first call is this rank's initialize() (it connects to D with its rank);
  /// each later one, after exchangePartial(), takes the next grant or the end of the run.
  /// @pre state() == Created or Exchanged; options().rank > 0
  void follow(const std::string& controlState);

  /// The protocol minor agreed with the DEM server (valid after initialize()/follow()).
  int demProtocolMinor() const;

  /// Q_split (protocol 1.5): the heat the gas removed from each coupling cell in its last step
  /// beyond what the DEM booked, J per m3 of coupling-cell volume (either sign), for the DEM server
  /// to give to the cell's particles at the start of its next window. Sent with the next
  /// exchange() (one value per coupling cell, grid().cellCount()) or exchangePartial() (one per
  /// listed cell: this rank's OWN contribution, still per m3 of coupling cell, not fluid-volume
  /// weighted; the DEM server sums the ranks'), then forgotten: call it before every exchange
  /// that has a split to send. The values are copied. Throws ClientError(Argument) when a value
  /// is not finite or when the DEM server agreed a protocol below 1.5 (it would drop the heat;
  /// check takesHeatToParticles() first); the size is checked by the exchange.
  /// @pre state() == Granted
  void setHeatToParticles(ConstView joulesPerCubicMetre);
  /// True when the DEM server takes Q_split (agreed protocol 1.5 or later).
  bool takesHeatToParticles() const;

  /// Where the last exchange() spent its time (zeros before the first).
  ExchangeTimes lastExchangeTimes() const;

  /// The sources of the last exchange(). @pre state() == Exchanged
  const Sources& sources() const;

  /// Ends the step: StepDone to O with the Courant number, ledgers (cumulative or per step, as
  /// documented by the participant) and the checkpoint files written for this step (paths
  /// relative to checkpointDir()); then waits for the next grant or Shutdown.
  /// @pre state() == Exchanged  @post state() == Granted or Finished
  void advance(double courant, const Ledgers& ledgers = Ledgers(),
               const std::vector<std::string>& checkpointFiles = std::vector<std::string>());

  /// Closes both connections. Safe to call in any state (also after an error); a second
  /// call is a no-op. @post state() == Finalized
  void finalize();

private:
  struct Impl;
  std::unique_ptr<Impl> _impl;
};

} // namespace client
} // namespace coredem
