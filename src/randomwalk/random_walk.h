#pragma once
// A per-query stochastic estimator of a layer stack's BSDF f(wi, wo): position-free Monte Carlo
// random walks through the layers (Guo, Hašan & Zhao 2018, "Position-free Monte Carlo simulation
// for arbitrary layered BSDFs", ACM TOG 37(6)), reading the same Stack and the same interface and
// phase-function code as the goniophotometer (physics/*.h), in double precision.
//
// Estimator (docs/rendering.md §1 has the derivation). A walk follows light exactly as the
// goniophotometer does: it enters along −wi, samples every interface and medium with the shared
// samplers and carries the same flux weights (spectral MIS in media). At every *non-delta* vertex v
// (a rough interface, a Lambertian base, a scattering event) it adds a next-event connection
// towards wo:
//
//     w_v · k_v(d_r) · Q_r(d_r) · (η_exit/η_r)² / |cos d_r|,
//
// where r is the region (medium) the connection leaves into, d_r the one direction in r that a
// chain of smooth interfaces maps onto wo (Snell's invariant η·sinθ and the azimuth are kept by
// every smooth reflection and refraction), k_v the vertex's flux kernel (f·|cos| of an interface
// or the HG phase function), and Q_r(d_r) the *exact* total throughput of all delta chains from v
// to the exit (any number of smooth reflections between smooth interfaces, unscattered
// transmittance e^{−τt/μ} through media), obtained by solving a small linear system once per wo
// (the adding equations of a 1-D ladder at a fixed Snell invariant). (η_exit/η_r)²/|cos| is the
// étendue Jacobian dω_r/dω_exit·cos_exit/cos_r (radiance compression through refractions).
//
// Every light path from wi to wo that carries a non-delta part has exactly one last non-delta
// vertex, and it is counted exactly once, at that vertex: the estimator is unbiased for the
// non-delta part of f (delta lobes, paths made only of smooth events, are left out, as
// Model::eval leaves them out). Because the light-side walk *is* the goniophotometer's particle
// and the connection replaces its binning, both estimate the same quantity.
//
// sample(wi) returns the walk's own exit: an unbiased "stochastic-weight" sample of the stack
// (E[weight·g(wo)] = ∫ f g |cos θo| dωo for every g). Its density has no closed form; pdf(wi, wo)
// is an unbiased stochastic estimate of it (docs/rendering.md §1.4): the sub-probability density
// p(wo | wi) of the exit direction of sample(wi) over the walks that leave the stack through at
// least one non-delta event (delta exits, absorbed, lost and cut-off walks are the missing mass:
// ∫ p dω = P(sample returns a non-delta exit)). The renderer keeps a proxy density in its MIS
// weights (docs/rendering.md §2 says why).
//
// Rough interfaces scatter once (Microsurface::Single, the default) or on their whole
// microsurface (Microsurface::Multiple, Heitz et al. 2016): then sample() follows the microsurface
// walk and every connection through such an interface uses one walk's unbiased estimate of its
// kernel or exit density (docs/rendering.md §1.6), so eval() and pdf() keep their expectations.
//
// Thread safety: const methods only; each call owns its random-number generator.

#include "core/rgb.h"
#include "core/rng.h"
#include "core/vec.h"
#include "layers/compiled_stack.h"
#include "layers/stack.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"
#include "physics/microsurface_walk.h"
#include "physics/polarization.h"

#include <cstdint>
#include <optional>
#include <type_traits>
#include <vector>

namespace lamina {

struct RandomWalkEstimate {
    Rgbd f{0.0};   ///< mean over walks, 1/sr
    Rgbd se{0.0};  ///< standard error of the mean
    std::uint64_t walks = 0;
};

/// A stochastic estimate of the exit density of sample() (docs/rendering.md §1.4), 1/sr.
struct RandomWalkPdf {
    double pdf = 0;  ///< mean over walks
    double se = 0;   ///< standard error of the mean
    std::uint64_t walks = 0;
};

struct RandomWalkSample {
    Vec3d wo;               ///< exit direction (below the surface: transmitted)
    Rgbd weight{0.0};       ///< flux weight: E[weight·g(wo)] = ∫ f g |cos θo| dωo
    bool is_delta = false;  ///< every event of the walk was a delta event (smooth interfaces,
                            ///< unscattered media): a delta lobe of the stack
};

/// The stack compiled for random walks (double precision, relative indices per interface).
class RandomWalkStack {
  public:
    /// `transport` (layers/transport_settings.h, as the goniophotometer's): the safety cap on
    /// events per walk, the refraction masking of the single-scattering rough dielectrics, and how
    /// the rough interfaces scatter: `Single`, the single-scattering microfacet BSDFs (the energy
    /// of the paths that meet a second facet is lost), or `Multiple`, the microsurface random walk
    /// of Heitz et al. 2016 (physics/microsurface_walk.h): sample() follows the walk to its exit,
    /// eval() and pdf() connect through the interface's multiple-scattering BSDF and exit density
    /// by the walk's unbiased stochastic evaluation (docs/rendering.md §1.6). With polarization,
    /// the walks carry the particle's polarization as the goniophotometer's polarized kernels do
    /// (docs/physics.md §8): sample() follows it, and eval() connects with it — a vertex's light
    /// leaves in the Mueller matrix of its facet for the walk's state, and the delta chains carry
    /// its s and p parts separately (a smooth chain lies in one plane of incidence). The estimates
    /// are those of unpolarized incident light.
    explicit RandomWalkStack(const Stack& stack, const TransportSettings& transport = {});

    const TransportSettings& transport() const { return transport_; }
    bool polarization() const { return transport_.polarization; }

    bool transmits() const { return transmits_; }
    /// Absolute indices of the ambient medium (above) and of the half-space below the base.
    double eta_top() const { return eta_.front(); }
    double eta_bottom() const { return eta_.back(); }
    int interfaces() const { return int(interfaces_.size()); }

    /// The non-delta part of f(wi, wo) (1/sr, no cosine), averaged over `walks` walks of the
    /// counter-based generator (seed, stream, walk index): deterministic for a seed. wi.z > 0;
    /// wo below the surface is the BTDF (zero for an opaque base). Standard error from the spread
    /// of the per-walk estimates.
    RandomWalkEstimate eval(const Vec3d& wi, const Vec3d& wo, std::uint64_t walks,
                            std::uint64_t seed, std::uint64_t stream) const;

    /// One walk's estimate of the non-delta f(wi, wo) with the caller's generator (renderers).
    Rgbd eval_once(const Vec3d& wi, const Vec3d& wo, ParticleRng& rng) const;

    /// Follows one particle from wi to its exit (empty when it is absorbed, lost or cut off).
    std::optional<RandomWalkSample> sample(const Vec3d& wi, ParticleRng& rng) const;

    /// Unbiased estimate of p(wo | wi), the sub-probability density (1/sr, solid angle) of the
    /// non-delta exits of sample(wi) at wo (either side), averaged over `walks` walks of
    /// (seed, stream, walk index); zero for wi.z ≤ 0 or wo.z = 0. Exact in expectation when
    /// pdf_is_unbiased(); otherwise see there. Delta exits (is_delta) have no density and are
    /// left out, as are walks that return no exit: ∫ p dω = P(non-delta exit).
    RandomWalkPdf pdf(const Vec3d& wi, const Vec3d& wo, std::uint64_t walks, std::uint64_t seed,
                      std::uint64_t stream) const;

    /// One walk's estimate of p(wo | wi) with the caller's generator.
    double pdf_once(const Vec3d& wi, const Vec3d& wo, ParticleRng& rng) const;

    /// The delta chains' exit probabilities are linear in the per-channel ladder (exact pdf)
    /// unless a scattering medium with per-channel extinction meets, in one delta chain, a
    /// per-channel weight that is not a flight through such a medium (a smooth conductor with
    /// per-channel Fresnel, an absorbing non-scattering medium with per-channel τ): then the
    /// spectral-MIS channel probabilities make the exit probability a non-linear function of the
    /// flux weights and pdf() is an approximation (docs/rendering.md §1.4). False only then.
    /// Multiple-scattering interfaces do not change it: each facet's exit enters the chain
    /// probability with its own weight (docs/rendering.md §1.6); the facet cap truncates sample,
    /// eval and pdf alike. Polarized walks: pdf() estimates the exit density of the unpolarized
    /// walk (its walks and branch probabilities are those of unpolarized light at every event),
    /// which differs from the polarized sample()'s by polarization's effect on the Fresnel
    /// choices: a proxy density (the renderer's use), and pdf_is_unbiased() is false.
    bool pdf_is_unbiased() const { return pdf_unbiased_; }

    /// The delta lobes of the stack for incidence wi (paths made only of smooth events and
    /// unscattered flights): the mirror lobe and, for a slab, the straight-through lobe, with their
    /// exact energies from the same delta-chain ladder (empty when the top interface is rough).
    struct DeltaExit {
        Vec3d direction;
        Rgbd energy;
    };
    std::vector<DeltaExit> delta_lobes(const Vec3d& wi) const;

    /// The delta-chain throughput Q for a connection towards wo: exposed for tests. Region r = 0 is
    /// the ambient medium, r = L (interfaces()) below the base.
    struct Connection;

  private:
    /// The stack as compile_stack<double> (layers/compiled_stack.h) builds it: `delta` (smooth
    /// or index-matched: no density, no connection), `multiple` (rough, scattering by the
    /// microsurface walk).
    using Interface = CompiledLayer<double>;
    using Medium = CompiledMedium<double>;

    struct WalkState;
    /// What a walk adds up: nothing (sample), f towards wo (eval), the exit density at wo (pdf;
    /// accumulated in channel 0 of the Rgbd).
    enum class Mode { Sample, Eval, Pdf };
    template <Mode kMode>
    void walk(const Vec3d& wi, const Vec3d& wo, ParticleRng& rng, const Connection* conn, Rgbd& f,
              std::optional<RandomWalkSample>* exit) const;
    /// The steps of a walk at interface k, met from wi_local by the walk's state ws: the next
    /// events towards wo (eval), the exit density at wo (pdf), strategy 1's weight at the exit,
    /// strategy 2 from the vertex interface, and the interface's event itself.
    void connect_at_interface(int k, const Vec3d& wi_local, WalkState& ws, ParticleRng& rng,
                              const Connection& conn, const Vec3d& wo, bool polarized,
                              Rgbd& f) const;
    void exit_density_at_interface(int k, const Vec3d& wi_local, WalkState& ws, ParticleRng& rng,
                                   const Connection& conn, const Vec3d& wo, Rgbd& f) const;
    double exit_mis(const Connection& conn, const WalkState& ws, const Interface& it,
                    const Vec3d& wi_local, const Vec3d& wo, int at) const;
    template <Mode kMode>
    void connect_from_vertex_interface(const Interface& vi, const Vec3d& wi_local, WalkState& ws,
                                       ParticleRng& rng, const Connection& conn, const Vec3d& wo,
                                       bool polarized, Rgbd& f) const;
    std::optional<BsdfSample<double>> sample_interface(const Interface& it, const Vec3d& wi_local,
                                                       WalkState& ws, ParticleRng& rng,
                                                       bool polarized) const;
    template <Mode kMode>
    bool traverse_medium(int region, WalkState& ws, ParticleRng& rng, const Connection* conn,
                         const Vec3d& wo, Rgbd& f) const;
    /// Strategy 2's direction ω into the vertex's region: the exit interface's transmission
    /// sampled from wo (its single-scattering sampler), with the balance-heuristic weight of that
    /// strategy against the vertex's proxy density (`proxy_pdf` × the survival to the depth).
    struct ExitDirection {
        const Interface* exit;  ///< the exit interface
        Vec3d wt;     ///< the sampled transmitted direction at the exit (pointing out of it)
        double pdf;   ///< its density
        Vec3d omega;  ///< −wt: the direction from the vertex towards the exit
        double mu;    ///< |cos θ| of ω
        double mis;   ///< the balance-heuristic weight
    };
    template <typename ProxyPdf>
    std::optional<ExitDirection> sample_exit_direction(const Connection& conn, const Vec3d& wo,
                                                       double depth, ParticleRng& rng,
                                                       const ProxyPdf& proxy_pdf) const;
    template <Mode kMode, typename Kernel, typename PdfChain, typename ProxyPdf>
    void connect_through_exit(const Connection& conn, const Vec3d& wo, double depth, const Rgbd& w,
                              ParticleRng& rng, const Kernel& kernel, const PdfChain& pdf_chain,
                              const ProxyPdf& proxy_pdf, Rgbd& f) const;
    double survival_proxy(int region, double path) const;
    static Rgbd eval_interface(const Interface& it, const Vec3d& wi, const Vec3d& wo);
    static double pdf_interface(const Interface& it, const Vec3d& wi, const Vec3d& wo);
    /// The sampling density of sample_interface's sample s from wi (what the interfaces' samplers
    /// report; the single-scattering proxy for a multiple-scattering interface); 0 for a delta
    /// sample.
    static double sample_density(const Interface& it, const Vec3d& wi, const BsdfSample<double>& s);
    /// One microsurface walk of a multiple-scattering interface from wi, calling
    /// `visit(connect)` at every facet, where connect(wo) is the facet's next-event estimate
    /// towards wo (MicrosurfaceConnection: exit density and the exit's flux weight).
    template <typename Visit>
    void visit_microsurface(const Interface& it, const Vec3d& wi, ParticleRng& rng,
                            Visit&& visit) const;
    /// The interface's kernel f(wi, wo)·|cos θo| (RGB): exact for single scattering, one walk's
    /// unbiased estimate for multiple scattering.
    Rgbd interface_kernel(const Interface& it, const Vec3d& wi, const Vec3d& wo,
                          ParticleRng& rng) const;
    /// The interface's exit density at wo times the probability that the delta chains `q` carry
    /// the walk, of flux weight w before the interface, to the stack's exit:
    /// pdf(wi, wo)·chain_probability(w·weight(wo), q) (docs/rendering.md §1.4), exact for single
    /// scattering, one walk's unbiased estimate for multiple scattering.
    /// Polarized walks: the Stokes vectors (per unit flux, per channel, f·|cos| units, in the
    /// tabulation frame of each direction) of the light a non-delta interface, met from wi by a
    /// particle in polarization state `state` with flux `w`, sends towards the n ≤ 2 directions
    /// d[j] (away from it): exact for single scattering, one walk's unbiased estimate (a polarized
    /// visiting walk, shared by the directions) for multiple scattering. `channels`: the states
    /// in use (0: the stack's).
    void emission(const Interface& it, const Vec3d& wi, const Vec3d* d, int n,
                  const StokesLanes<double>& state, const Rgbd& w, ParticleRng& rng,
                  StokesRgb<double>* out, int channels = 0) const;
    /// Strategy 2 for a polarized walk (eval): as connect_through_exit, the vertex's light
    /// `emit(ω, out)` (Stokes vectors per unit flux) crossing the exit interface in the Mueller
    /// matrix of its facet.
    template <typename Emit, typename ProxyPdf>
    void connect_through_exit_polarized(const Connection& conn, const Vec3d& wo, double depth,
                                        const Rgbd& w, ParticleRng& rng, const Emit& emit,
                                        const ProxyPdf& proxy_pdf, Rgbd& f) const;
    double interface_pdf_chain(const Interface& it, const Vec3d& wi, const Vec3d& wo, const Rgbd& w,
                               const Rgbd& q, ParticleRng& rng) const;
    /// Calls f(std::bool_constant<anisotropic_>{}): the instance of the GGX samplers and
    /// microsurface walks (GGX::lanes) the stack needs, as the goniophotometer chooses it.
    template <typename F>
    decltype(auto) with_roughness(F&& f) const {
        if (anisotropic_) return f(std::true_type{});
        return f(std::false_type{});
    }

    std::vector<Interface> interfaces_;  ///< top to bottom (compile_stack's layers)
    std::vector<Medium> media_;          ///< per region 0..L (0 and L empty): the layers' media
    std::vector<double> eta_;            ///< absolute index per region 0..L
    bool transmits_ = false;
    bool pdf_unbiased_ = true;
    /// Some rough interface is anisotropic (CompiledStack::anisotropic): every sampler and
    /// microsurface walk takes the general instance of the GGX formulas, as the goniophotometer's
    /// kernel does; isotropic stacks keep the isotropic instance and their estimates.
    bool anisotropic_ = false;
    TransportSettings transport_;
    int channels_ = 1;  ///< polarization states per particle (CompiledStack::polarization_channels)
};

}  // namespace lamina
