#pragma once
/// @file
/// Particle contact laws (docs/physics.md §2.1): the registry of the family, the row of the pair
/// table and the choice of the law. The contact module (contacts.h) runs its owners' pass for
/// the law chosen by `models: {contact: ...}`: particle–particle pairs and every wall (planes,
/// cylinders, cones, meshes) with the same law.
///
/// A contact law is a model (model_list.h: name, doc, Params, params()) that also declares
///
///   template <class S> using PairT = …;   // a material pair's properties (a row of the pair
///   using Pair = PairT<double>;           //   table), S the scalar type (lanes.h)
///   template <class S> using ContactT = …;  // one contact's parameters
///   template <class Material> static Pair mix(const Params&, const Material& a, const Material&
///   b);
///                                         // host: the row of materials a and b (walls: a, a)
///   static double collisionTime(const Params&, const Pair&, double meff, double reff);
///                                         // host: the contact's time scale that Δt_DEM,max
///                                         //   resolves (dt_factor steps)
///   static double stableStep(const Params&, const Pair&, double meff, double reff);
///                                         // host: the largest Δt the integrator keeps the
///                                         //   contact stable with
///   template <class S, class Load> DEM_HD static PairT<S> gather(const Load& load);
///                                         // PairT<S>{load(&Pair::member)…}: rows into lanes
///   template <class S> DEM_HD static ContactT<S> contact(const PairT<S>&, S meff, S reff);
///                                         // per contact: m* = m_i m_j/(m_i + m_j),
///                                         //   R* = R_i R_j/(R_i + R_j) (walls: m_i, R_i)
///   template <class S> DEM_HD static ContactResultT<S> evaluate(const ContactT<S>&, Vec3T<S> n,
///       S deltaN, Vec3T<S> vij, S lij, Vec3T<S> deltaTOld, double dt);
///                                         // force on i, torque on i, new δ_t, n × f_t
///
/// in the conventions of contact_common.h. The pair is evaluated once, by its owner, and j
/// receives −force and L_ji n × f_t; a law is written mirror-exact (evaluating from j's side
/// gives exactly that) and without FMA-sensitive reassociation, so that the cpu backend's lanes
/// give the bits of the scalar path. Its history is the tangential displacement δ_t (three
/// doubles per contact, the state file's histDisp).
///
/// Adding a contact law: its kernel header (the declaration above), its name in ContactLaws
/// below (appended: the ids of the others, and so earlier configuration hashes, stay), its test
/// and its docs/case-schema.md rows. Its `models:` value and parameter keys
/// ("contact.<law>.<parameter>", entering the kernels through mix()), their validation and
/// hashing, the pair table and the owners' pass for it come from the declaration
/// (docs/architecture.md).

#include <type_traits>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/contact_common.h"
#include "coredem/dem/kernels/hertz_mindlin_contact.h"
#include "coredem/dem/kernels/lsd_contact.h"
#include "coredem/dem/kernels/model_list.h"

namespace coredem::dem::kernels {

/// The contact laws, in id order (the registration line).
using ContactLaws = ModelList<LinearSpringDashpot, HertzMindlin>;

/// A contact law's id (its position in ContactLaws; the configuration hash uses it). The default
/// has a name; any law's id is contactLaw<Law>().
enum class ContactLaw : int {
  LinearSpringDashpot = 0, ///< kernels/lsd_contact.h, the default
  HertzMindlin = 1         ///< kernels/hertz_mindlin_contact.h
};

template <class Law>
constexpr ContactLaw contactLaw() {
  return static_cast<ContactLaw>(modelId<Law, ContactLaws>);
}
static_assert(contactLaw<LinearSpringDashpot>() == ContactLaw::LinearSpringDashpot);
static_assert(contactLaw<HertzMindlin>() == ContactLaw::HertzMindlin);

/// A row of the pair table for the laws of List: the Pair of one of them (a union: as large as
/// the largest, so that a law's rows do not grow with the others). Plain data, copied to the
/// device as is.
template <class List>
union PairRow;
template <class M, class... Rest>
union PairRow<ModelList<M, Rest...>> {
  typename M::Pair first;
  PairRow<ModelList<Rest...>> rest;

  /// The row holding law L's Pair p.
  template <class L>
  static PairRow make(const typename L::Pair& p) {
    PairRow row{};
    if constexpr (std::is_same_v<L, M>)
      row.first = p;
    else
      row.rest = PairRow<ModelList<Rest...>>::template make<L>(p);
    return row;
  }
  /// Law L's Pair (the row holds L's).
  template <class L>
  DEM_HD const typename L::Pair& of() const {
    if constexpr (std::is_same_v<L, M>)
      return first;
    else
      return rest.template of<L>();
  }
};
template <>
union PairRow<ModelList<>> {};

/// A row of the engine's pair table (EngineSetup::pairs).
using ContactPair = PairRow<ContactLaws>;

} // namespace coredem::dem::kernels
