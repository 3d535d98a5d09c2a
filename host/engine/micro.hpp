#pragma once
/// Micromechanics of a granular specimen (Tang et al. 2025, Secs. 4.2-4.4; definitions in docs/running.md,
/// "Micromechanics"; the networks split at the mean normal force as Radjai et al. 1998, PRL 80:61, do):
/// coordination, strong and weak networks, fabric and force anisotropy (Ouadfel & Rothenburg 2001, 3D, vector
/// tangential form), directional distributions, Love-Weber stress, and the force-chain export. Everything works on
/// a ContactSet, a host copy of the touching contacts, taken from a running simulation or from a snapshot.
///
/// Conventions: SI; stress compression positive; each contact's normal n points from ball a to ball b (or
/// to the boundary), and the force is the one a exerts on b (or on the boundary): f = fn n + ft.
#include <array>
#include <string>
#include <vector>

#include "host/io/io_hdf5.hpp"
#include "kernels/core/domain.hpp"
#include "kernels/core/vec3.hpp"

namespace dem {

class Simulation;

enum class Boundary : int { kNone = 0, kPlaten = 1, kMembrane = 2 };

struct ContactRecord {
  int a = 0;             ///< ball index (gid)
  int b = -1;            ///< second ball (gid), -1 at a boundary
  Boundary boundary = Boundary::kNone;
  Vec3 normal;           ///< unit, a -> b (or a -> boundary)
  Vec3 point;            ///< contact point (m)
  Vec3 branch;           ///< x_b - x_a (ball-ball) or point - x_a (boundary), m
  Real fn = 0;           ///< normal force (N), > 0
  Vec3 ft;               ///< tangential force on b (N), perpendicular to normal
  bool in_volume = true; ///< contact point inside the analysed volume (false: kept only for per-ball counts)
};

struct ContactSet {
  std::vector<Vec3> x;          ///< ball centres by gid (m)
  std::vector<Real> radius;     ///< m
  std::vector<ContactRecord> contacts;  ///< touching contacts only
  std::vector<char> inside;     ///< balls of the analysed volume (empty: all)
};

struct ContactCopy;  // host/engine/state_copy.hpp

/// Touching contacts of a simulation (or of a copy of its state, with its contacts). Analytic walls count as
/// platens, facets as membrane.
ContactSet contact_set(const ContactCopy& c);
ContactSet contact_set(Simulation& sim);
/// The same to and from a snapshot file's /contacts group. contact_set(file) throws std::runtime_error
/// naming the file when it holds no contacts.
io::ContactTable contact_table(const ContactSet& s);
ContactSet contact_set(const io::SnapshotFile& f, const std::string& path);

using Tensor = std::array<Real, 9>;  ///< row-major 3 x 3

/// Which contacts a statistic uses.
enum class Network { kAll, kStrong, kWeak };

/// Coordination (Sec. 4.3, Eq. 17; Thornton 2000). Contacts counted: ball-ball and ball-membrane (as the
/// paper does), platens excluded.
struct Coordination {
  Real z = 0;            ///< 2 Nc / Np with Nc = ball-ball + ball-membrane contacts
  Real z_balls = 0;      ///< 2 Nc_bb / Np
  Real z_mech = 0;       ///< (2 Nc_bb - N1) / (Np - N0 - N1), ball-ball contacts (rattlers excluded)
  std::vector<long> on;  ///< on[n]: balls with exactly n contacts (same contacts as z), per network
};
Coordination coordination(const ContactSet& s, Network net = Network::kAll);

/// Strong and weak networks split at the mean normal force of the ball-ball contacts (Radjai et al. 1998).
struct NetworkStats {
  long contacts = 0, particles = 0;   ///< particles: balls with at least one contact of the network
  Real mean_fn = 0, mean_ft = 0;      ///< N (|ft| for the tangential)
  Tensor stress{};                    ///< partial Love-Weber stress over the given volume (Pa)
};
struct Networks {
  Real threshold = 0;                 ///< mean fn of all ball-ball contacts (N)
  NetworkStats all, strong, weak;
  Real fn_ratio = 0, ft_ratio = 0;    ///< strong / weak mean normal and tangential force (Fig. 10)
};
Networks networks(const ContactSet& s, Real volume);

/// Second-order anisotropy of contact normals, normal and tangential forces (Ouadfel & Rothenburg 2001):
/// E(n) = (1 + a^c:nn)/4pi, fn(n) = f0 (1 + a^n:nn), ft(n) = f0 (a^t.n - (n.a^t.n) n). Ball-ball contacts.
struct Anisotropy {
  long contacts = 0;
  Tensor fabric{}, ac{}, an{}, at{};
  Real f0 = 0;                      ///< mean normal force (N)
  Real a_c = 0, a_n = 0, a_t = 0;   ///< sign(a:s) sqrt(3/2 a:a), s = deviator of the reference stress
};
/// `reference` sets the sign of the scalars (the specimen's stress; along z compression when zero).
Anisotropy anisotropy(const ContactSet& s, Network net, const Tensor& reference);

/// Directional distribution against the angle theta between the contact normal and the z axis (n and -n
/// both counted, theta in [0, 180] deg, bins of equal solid angle): density per unit solid angle
/// (integrates to 1 over the sphere; (1 + a^c:nn)/4pi for a second-order fabric), mean fn and mean |ft|.
struct RoseBin {
  Real theta_deg = 0;      ///< bin centre
  long count = 0;
  Real density = 0, mean_fn = 0, mean_ft = 0;
};
std::vector<RoseBin> rose(const ContactSet& s, int bins, Network net = Network::kAll);

/// q/p of the stress-force-fabric relation, sigma / p = I + (2/5)(a^c + a^n + 3/2 a^t), taken with the
/// tensors: for tensors coaxial with the stress it is (2/5)(a_c + a_n + 3/2 a_t), and where they are not
/// (an isotropic state, whose anisotropies point anywhere) the scalars' signs mean nothing.
Real sff_stress_ratio(const Anisotropy& a);

/// The cube of side `edge` centred at `centre`: balls by centre, contacts by contact point. Contact
/// averages (2 Nc / Np, forces, fabric, stress) use the contacts inside; per-ball counts (O_n, Z_mech) use
/// every contact of the balls inside, so balls at the faces are not undercounted. Throws
/// std::invalid_argument naming the cube and the specimen's extent when it does not fit.
ContactSet restrict_to_cube(const ContactSet& s, const Vec3& centre, Real edge);

/// Force chains for ParaView (legacy VTK polydata): a segment between the centres of every ball-ball
/// contact with its normal force (N) and strong flag (fn > mean). Atomic write.
void write_force_chains_vtk(const std::string& path, const ContactSet& s);

/// Scalar signed anisotropy of a deviatoric tensor a against reference stress s.
Real signed_magnitude(const Tensor& a, const Tensor& reference);

}  // namespace dem
