"""The ``rod`` representation: the beam as a 1D ``flexcomp`` rod, MuJoCo's discrete elastic
rod (the replacement of the cable plugin and ``<composite>``, removed in MuJoCo 4.0).

What is built (internal units, :mod:`mjeap.model.mjcf` conventions)::

    <flexcomp name="rod" type="direct" dim="1" point="..." radius="t/2">
      <elasticity young="E" poisson="nu" damping="(beta - h) t/w" section="box" sectionsize="t/2 w/2"/>
      <edge equality="true" solref="h/100 1" solimp="0.9999 ..."/>
      <pin id="0 1"/>
    </flexcomp>

* **Vertices by the midpoint rule.** With ds = L / N the N + 2 points sit at
  x_k = (k - 1/2) ds, k = 0 .. N + 1, all ds apart. Points 0 and 1 are pinned to the clamp
  (``<pin id="0 1"/>`` clamps the first edge and its material frame), so the bending
  vertices 1 .. N sit at the hinge chain's hinges x_j = (j + 1/2) ds. The rod's bending
  energy at a vertex between edges of lengths l0, l1 is k |kappa b|^2 with
  k = E I / (l0 + l1) = EI / (2 ds) and |kappa b| = 2 tan(theta / 2): to second order a
  hinge of stiffness EI / ds, the hinge chain's, each representing the segment of length
  ds around it (its Voronoi length). The last edge therefore runs half a segment past the
  tip: the beam ends at its midpoint, where the tip site is. (With the last point at the tip
  the last vertex would represent 0.75 ds, a first-order error of ds / 4L in the tip angle
  under a uniform moment.) The curvature measure 2 tan(theta / 2) stiffens a vertex by
  theta^2 / 3 relative to the hinge chain's exact angle: a second-order error, -0.25 % of
  the curvature at a tip angle of 2 rad and 0.2 % of L at P L^2 / EI = 10 on 20 segments.
* **Section.** ``section="box"`` with half-sizes (t/2, w/2) and E = 12 EI / (w t^3), so the
  weak axis (bending in the clamp's x-y plane) carries the catalog's EI; the strong axis
  (E I (w/t)^2) and the torsion (G J) come with the box. ``radius`` is the minor half-size
  (MuJoCo 4.0 requires it for box sections). The rod has one section and one Young's
  modulus: tapered beams (EI(x) varying, the piezo bimorphs) are refused.
* **Tip frame.** The vertices do not rotate, so the last edge is a rigid body: ``rod_tip``,
  under vertex N's body with a hinge about the clamp's z axis, carries vertex N + 1 at
  (ds, 0, 0) (the flexcomp's own body for that point is removed and the flex's vertex moved
  onto the frame). Its origin is hinge N - 1, as the hinge chain's last link, whose mass,
  centre and inertia it takes: the tip site, the tip-load body, the rigid extension and a
  payload ride on it exactly. A payload must sit on this last link: elsewhere it would
  hang on a vertex that does not rotate (refused). (A frame held along the edge by a
  ``connect`` equality instead lags the edge by the soft constraint's violation under a tip
  couple: 6e-4 of the tip curvature at kappa L = 0.3, measured.)
* **Mass.** The other vertex bodies are point masses with three slide joints. Each link of
  the hinge layout but the last (hinge j to hinge j + 1) is lumped onto its two end
  vertices by the lever rule, keeping its mass and centre; the clamp half of link 0 rides
  on the pinned vertex 1.
* **Inextensible edges.** The edge equality is a MuJoCo soft constraint: solimp 0.9999 and
  a time constant of h / 100 (under ``discrete`` equality rows are taken implicitly and as
  authored, see EDGE_TIMECONST) hold the edges to 1.6e-4 of their length at
  P L^2 / EI = 10.
* **MuJoCo 3.x** compiles this rod only under the CG solver (Newton refuses a flex vertex
  on a jointed body: "flex with general attachments requires solver='CG'"), and then it
  blows up on its first steps (mjWARN_BADQACC, measured on 3.17.0): the rod is refused
  there. (A plain flexcomp rod without the tip frame does run on 3.17, with the same
  in-plane statics as 4.0 but no twist joints and one bending stiffness per vertex, the
  weak axis's, where 4.0 has the box's two principal ones.)
* **Integrator.** MuJoCo 4.0 refuses rod elasticity under ``implicit`` and
  ``implicitfast``; ``discrete`` integrates it implicitly (as backward Euler does the hinge
  chain's springs), so the rod has no stability limit of its own and the scene steps it at
  min(T_1 / 50, beta / 2) like the hinge chain under ``discrete``.
* **Damping.** The flex's own Rayleigh damping (``elasticity damping``): the file is
  self-contained. MuJoCo damps a box section's weak axis by coefficient x sqrt(k1 k2), the
  strong one by coefficient x k2 (equal damping ratios), so the coefficient is
  (beta - h) t / w: bending then gets (beta - h) x its stiffness, and backward Euler adds
  h x its stiffness itself (Rayleigh beta = h), beta from the scene's first mode
  (:mod:`mjeap.simulation.scene`).
* **Read-outs** (:class:`RodView`): the bending angle at vertex j is the turn between its
  two edges, in the clamp's x-y plane, from the vertex positions (the slides are offsets in
  the clamp frame); rates from their velocities. A drive's internal moment M_j acts as
  equal and opposite couples on the two edges at vertex j: edge k carries M_k - M_{k+1},
  applied as forces +-C / l along the edge normal at its two vertices (the last edge, the
  tip frame: a torque on its hinge), the generalised force of the hinge moments, as the
  cable's bending dofs take them. Those forces follow the edges, so moments set on a
  scene are applied again before each step (the drives set theirs every step anyway).

Refused on the rod, each with its reason (:class:`RodBuilder`):

* ``engine="native"``: a native drive is a ``filterexact`` actuator on a fixed tendon that
  sums the bending joints (:mod:`mjeap.drives.native`). The rod has no bending joints: its turning
  angles are functions of the vertex positions. A native form would need (a) the moment
  as a transmission, e.g. a ``site`` actuator with gear (0 0 0 0 0 1) on the tip frame for a
  moment that is the same at every vertex (a uniform internal moment is a couple on the last
  edge), and (b) per-vertex angles for anything per hinge: Dadras et al. 2021's back-relaxation
  (a Maxwell arm per hinge, a fixed tendon theta_j - r_j) and the piezo's width-weighted
  moments. MuJoCo 4.0's flex offers no per-vertex bending coordinate.
* ``engine="threaded"``: its moments are forces along the present edge normals, not fixed
  generalised forces that could be precomputed as ``qfrc_applied`` controls.
* ``attach`` / :class:`~mjeap.System`: ``MjSpec.attach`` of the clamp body carries the flex
  but not the per-edge twist bodies, which the flexcomp puts under the world body; MuJoCo
  then refuses the box-section rod ("1D flex elasticity with box section requires per-edge
  twist joints", measured). Attaching the twist bodies to the host's world as well might
  make it compile; not built.
* accuracy targets (:mod:`mjeap.simulation.accuracy`): its error model is the hinge chain's.
"""
from __future__ import annotations

from typing import Optional

import mujoco
import numpy as np

from ..errors import ParameterError
from ..units import UnitSystem
from .discretize import BeamLayout
from .mjcf import (ATTACHED_WHOLE, BEAM_RGBA, FIXED_BENDING_FORCES, HINGE_CHAIN_ERROR, HINGE_TENDON, BeamBuilder,
                   BeamHandles, element_finder, set_inertial, register)
from .views import BeamView, into

#: impedance of the rod's edge constraints: 1 - d = 1e-4 of the violation's restoring
#: force is left to the reference spring (MuJoCo's stiffest, mjMAXIMP)
SOLIMP = [0.9999, 0.9999, 0.001, 0.5, 2.0]
#: time constant of the edge equality rows as a fraction of the timestep: under 'discrete'
#: MuJoCo evaluates a row's solref spring at the end of the step (stable for any solref) and
#: leaves equality rows as authored (refsafe does not raise them to 2 h), so the edges are
#: held nearly rigid: at 2 h they stretched 1.4e-3 at P L^2 / EI = 10 on 20 segments (and
#: as N^2), at h / 100 1.6e-4, the floor that the impedance 0.9999 leaves
EDGE_TIMECONST = 0.01
#: relative spread of EI(x) above which a beam counts as tapered
TAPER_TOLERANCE = 1e-9


class RodBuilder(BeamBuilder):
    """1D flexcomp rod (discrete elastic rod with a box section), see the module docstring."""

    representation = "rod"
    #: 3 slides per vertex, a twist hinge per edge, the tip frame's hinge
    dofs_per_hinge = 4
    #: flexcomp rods refuse 'implicit' and 'implicitfast' (MuJoCo 4.0): 'discrete' takes the
    #: rod's elasticity implicitly
    integrators = ("discrete",)
    default_integrator = "discrete"
    name = "rod"
    capabilities = frozenset()
    instead = {HINGE_TENDON: "the rod has no bending joints: its turning angles are functions of the flex vertices "
                             "(see mjeap.model.rod for what a native form would need)",
               FIXED_BENDING_FORCES: "the rod's moments act as forces along its present edge normals, which turn "
                                     "with its configuration",
               HINGE_CHAIN_ERROR: "the rod's discretisation error is its flex's, not the hinge chain's",
               ATTACHED_WHOLE: "MjSpec.attach of the clamp body carries the rod's flex but not its per-edge twist "
                               "bodies, which the flexcomp puts under the world body, and MuJoCo refuses a "
                               "box-section rod without them ('requires per-edge twist joints')"}

    def unavailable_reason(self):
        from ..versions import MUJOCO_VERSION, mujoco_major
        if mujoco_major() >= 4:
            return None
        return (f"MuJoCo {MUJOCO_VERSION} compiles the rod only under the CG solver (Newton refuses a flex vertex on "
                "its jointed tip frame) and then blows up on its first steps; it needs MuJoCo 4.x (use 'hinge', or the "
                "cable, here)")

    def integrator_reason(self, integrator):
        if integrator in self.integrators:
            return None
        return ("MuJoCo 4.0 does not integrate 1D flexcomp rod elasticity under 'implicit' or 'implicitfast' "
                "(it refuses the model); 'discrete' integrates it implicitly")

    def layout_reason(self, layout: BeamLayout) -> Optional[str]:
        k = layout.hinge_stiffness
        if np.ptp(k) > TAPER_TOLERANCE * np.mean(k):
            return (f"a flexcomp rod has one section and one Young's modulus, and this beam is tapered (EI from "
                    f"{k.min() * layout.ds:.4g} to {k.max() * layout.ds:.4g} N m^2)")
        return None

    def implicit_stiffness(self, integrator):
        return True

    def _section(self, layout: BeamLayout):
        """(E, t, w) in SI: the box section whose weak-axis E w t^3 / 12 is the beam's EI."""
        EI = float(layout.hinge_stiffness[0] * layout.ds)
        t, w = layout.thickness, float(layout.hinge_width[0])
        return 12 * EI / (w * t**3), t, w

    def skeleton_xml(self, layout, units):
        N, ds = layout.segments, layout.ds
        xs = (np.arange(N + 2) - 0.5) * ds / units.length
        points = " ".join(f"{x:.12g} 0 0" for x in xs)
        E, t, w = self._section(layout)
        t_, w_ = t / units.length, w / units.length
        mass = float(layout.link_mass.sum()) / units.mass
        rgba = " ".join(map(str, BEAM_RGBA))
        return (
            f'<flexcomp name="{self.name}" type="direct" dim="1" point="{points}" radius="{0.5 * t_:.12g}" '
            f'mass="{mass:.12g}" rgba="{rgba}">'
            f'<contact contype="0" conaffinity="0" selfcollide="none"/>'
            f'<elasticity young="{E / units.pressure:.12g}" poisson="{layout.poisson_ratio:.12g}" damping="0" '
            f'section="box" sectionsize="{0.5 * t_:.12g} {0.5 * w_:.12g}"/>'
            f'<edge equality="true" solimp="{" ".join(map(str, SOLIMP))}"/>'
            f'<pin id="0 1"/>'
            f'</flexcomp>')

    def build(self, spec, layout, units):
        N, ds = layout.segments, layout.ds
        n = self.name
        # lumped masses: link j (hinge j to hinge j + 1) onto its end vertices j + 1 and j + 2
        # (ds apart) by the lever rule; the last link is the tip frame
        frac = (layout.link_com[:-1] - layout.link_start[:-1]) / ds
        vm = np.zeros(N + 1)
        vm[1:N] += layout.link_mass[:-1] * (1 - frac)
        vm[2:N + 1] += layout.link_mass[:-1] * frac
        for k in range(2, N + 1):
            spec.body(f"{n}_{k}").mass = vm[k] / units.mass
        # hinge 0 sits on the pinned vertex 1: a static marker body there for the read-outs
        spec.body("clamp").add_body(name=f"{n}_1", pos=[0.5 * ds / units.length, 0, 0])
        # the tip frame: the last edge as a rigid body, hinged about z at vertex N, carrying
        # vertex N + 1 and the last link
        tip = spec.body(f"{n}_{N}").add_body(name=f"{n}_tip")
        tip.add_joint(name=f"{n}_tip", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
        set_inertial(tip, layout.link_mass[-1], [layout.link_com[-1] - layout.link_start[-1], 0, 0],
                      layout.link_inertia[-1], units)
        flex = spec.flex(n)
        vb = list(flex.vertbody)
        vb[N + 1] = f"{n}_tip"
        flex.vertbody = vb
        v = list(flex.vert)
        v[3 * (N + 1):3 * (N + 2)] = [ds / units.length, 0.0, 0.0]
        flex.vert = v
        spec.delete(spec.body(f"{n}_{N + 1}"))      # after the flex no longer names it
        links = [f"{n}_{k}" for k in range(1, N + 1)]
        _, t, w = self._section(layout)
        return BeamHandles("rod", links, [], tip_body=f"{n}_tip",
                           extra={"flex": n, "tip_joint": f"{n}_tip", "aspect": t / w})

    def payload_host(self, layout, handles, payload):
        j = layout.link_containing(min(payload.position, layout.length))
        if j < layout.segments - 1:
            raise ParameterError("payload.position", payload.position,
                                 f"a position on the rod's last link (>= {layout.link_start[-1]:.4g} m) or past the tip",
                                 "the rod's vertices are point masses that do not rotate: a rigid payload rides on "
                                 "its tip frame only")
        return handles.tip_body

    def set_damping(self, spec, handles, beta, per_hinge, dof_damping=None):
        # the flex's own Rayleigh damping. MuJoCo 4.0 damps a box section's weak axis with
        # coefficient x sqrt(k1 k2) (the strong axis with coefficient x k2), equalising the
        # damping ratios of the two axes: with k1 / k2 = (t / w)^2 the coefficient that gives
        # the weak (bending) axis beta k1 is beta t / w
        spec.flex(handles.extra["flex"]).damping = float(beta) * handles.extra["aspect"]

    def finish(self, spec, handles, timestep):
        # the edge constraints' time constant, EDGE_TIMECONST x h
        for e in spec.equalities:
            if e.type == mujoco.mjtEq.mjEQ_FLEX and e.name1 == handles.extra["flex"]:
                e.solref = [EDGE_TIMECONST * timestep, 1.0]

    def linearize(self, model, handles, layout, units, angles=None):
        """Mass and stiffness in the hinge angles theta (the rod's in-plane bending, as the
        hinge chain's joint coordinates): q(theta) places the vertices (edges exactly ds)
        and the tip frame, J = dq/dtheta, M = J' M_q J, and K = -dQ/dtheta of the
        generalised forces Q = J' f by central differences, split into the elastic part
        (f = qfrc_passive: the rod's elasticity) and gravity's (f = -qfrc_bias at rest;
        the change of J with theta gives its geometric stiffness). The constraint forces do
        no work along q(theta). Under 'discrete' the whole elastic part is implicit."""
        from .modes import Linearization
        view = self.view(model, handles, layout, units)
        d = mujoco.MjData(model)
        N = layout.segments
        theta0 = np.zeros(N) if angles is None else np.asarray(angles, dtype=float)

        def at(theta):
            q = model.qpos0.copy()
            view.write_angles(q, theta)
            d.qpos[:] = q
            d.qvel[:] = 0
            mujoco.mj_forward(model, d)
            return view.jacobian(d.qpos)

        J = at(theta0)
        Mq = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, d, Mq)
        M = J.T @ Mq @ J
        eps = 1e-6
        Ke, Kg = np.zeros((N, N)), np.zeros((N, N))
        for i in range(N):
            f = []
            for s in (eps, -eps):
                th = theta0.copy()
                th[i] += s
                Ji = at(th)
                f.append((Ji.T @ d.qfrc_passive, Ji.T @ -d.qfrc_bias))
            Ke[:, i] = -(f[0][0] - f[1][0]) / (2 * eps)
            Kg[:, i] = -(f[0][1] - f[1][1]) / (2 * eps)
        Ke = 0.5 * (Ke + Ke.T)
        Kg = 0.5 * (Kg + Kg.T)
        return Linearization(M, Ke, Kg, Ke.copy())

    def view(self, model, handles, layout, units, prefix="", find=None):
        return RodView(model, handles, layout, units, prefix, element_finder(model, prefix, find), self.name)


class RodView(BeamView):
    """The rod in a compiled model: bending from its vertex positions (the slides of the
    vertex bodies are offsets in the clamp frame; the last edge is the tip frame, its
    direction the tip hinge's angle), moments as forces on its vertices and a torque on the
    tip frame."""

    moments_follow_geometry = True

    def __init__(self, model: mujoco.MjModel, handles: BeamHandles, layout: BeamLayout, units: UnitSystem,
                 prefix: str, find, name: str = "rod"):
        self.model = m = model
        N = self.N = layout.segments
        self.ds = layout.ds / units.length
        body = lambda n: find(mujoco.mjtObj.mjOBJ_BODY, n)  # noqa: E731
        vb = [body(f"{name}_{k}") for k in range(2, N + 1)]
        jnt = m.body_jntadr[vb]
        if np.any(m.body_jntnum[vb] != 3):
            raise ParameterError("model", prefix + name, "a flexcomp rod whose vertex bodies have three slide joints")
        self.q_adr = m.jnt_qposadr[jnt]                 # x, y, z of vertices 2 .. N
        self.v_adr = m.jnt_dofadr[jnt]
        tj = find(mujoco.mjtObj.mjOBJ_JOINT, handles.extra["tip_joint"])
        self.tip_q, self.tip_v = int(m.jnt_qposadr[tj]), int(m.jnt_dofadr[tj])
        twist = [j for j in range(m.njnt)
                 if (mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or "").startswith(f"{prefix}{name}_twist")]
        self.twist_q, self.twist_v = m.jnt_qposadr[twist], m.jnt_dofadr[twist]
        self.dofs = np.concatenate([self.v_adr, self.v_adr + 1, self.v_adr + 2, [self.tip_v], self.twist_v]).astype(int)
        self.flex = find(mujoco.mjtObj.mjOBJ_FLEX, handles.extra["flex"])
        # rest positions (clamp frame) of the N + 2 vertices
        self.X0 = np.zeros((N + 2, 3))
        self.X0[:, 0] = (np.arange(N + 2) - 0.5) * self.ds
        # the bending records of the flex after their count: 10 numbers per interior vertex,
        # k1 and k2 - k1 at 4 and 5 (MuJoCo 4.0, mjModel.flex_bending)
        a = int(m.flex_bendingadr[self.flex])
        if int(m.flex_bending[a]) != N:
            raise ParameterError("model", prefix + name, f"a rod with {N} bending vertices")
        self._k_idx = np.array([a + 1 + 10 * r + c for r in range(N) for c in (4, 5)])
        self._k0 = m.flex_bending[self._k_idx].copy()
        self.data = None

    # -- geometry --------------------------------------------------------------------------
    def positions(self, qpos: np.ndarray) -> np.ndarray:
        """The N + 2 vertices in the clamp frame (internal), from ``qpos``."""
        P = self.X0.copy()
        P[2:-1, 0] += qpos[self.q_adr]
        P[2:-1, 1] += qpos[self.q_adr + 1]
        P[2:-1, 2] += qpos[self.q_adr + 2]
        psi = qpos[self.tip_q]
        P[-1] = P[-2] + (self.ds * np.cos(psi), self.ds * np.sin(psi), 0.0)
        return P

    def _edges(self, P):
        e = np.diff(P[:, :2], axis=0)                  # (N + 1, 2), in the bending plane
        return e, np.einsum("ij,ij->i", e, e)

    def angles(self, out=None):
        e, _ = self._edges(self.positions(self.data.qpos))
        phi = np.arctan2(e[:, 1], e[:, 0])
        a = np.diff(phi)
        return into((a + np.pi) % (2 * np.pi) - np.pi, out)

    def rates(self, out=None):
        e, l2 = self._edges(self.positions(self.data.qpos))
        qv = self.data.qvel
        v = np.zeros((self.N + 1, 2))                  # vertices 0 .. N
        v[2:, 0], v[2:, 1] = qv[self.v_adr], qv[self.v_adr + 1]
        de = np.diff(v, axis=0)
        w = np.empty(self.N + 1)                       # edge rotation rates; the last: the tip frame's
        w[:-1] = (e[:-1, 0] * de[:, 1] - e[:-1, 1] * de[:, 0]) / l2[:-1]
        w[-1] = qv[self.tip_v]
        return np.diff(w)

    def write_angles(self, qpos, angles):
        phi = np.concatenate([[0.0], np.cumsum(angles)])       # edge directions, the pinned edge 0
        P = self.X0.copy()
        for k in range(1, self.N):                              # vertex k + 1 from vertex k along edge k
            P[k + 1, 0] = P[k, 0] + self.ds * np.cos(phi[k])
            P[k + 1, 1] = P[k, 1] + self.ds * np.sin(phi[k])
        qpos[self.q_adr] = P[2:-1, 0] - self.X0[2:-1, 0]
        qpos[self.q_adr + 1] = P[2:-1, 1]
        qpos[self.q_adr + 2] = 0.0
        qpos[self.tip_q] = phi[-1]
        qpos[self.twist_q] = 0.0

    def zero_rates(self, qvel):
        qvel[self.dofs] = 0

    def jacobian(self, qpos) -> np.ndarray:
        """dq/dtheta (nv x N) at ``qpos``: bending hinge j (vertex j + 1) rotates everything
        beyond it about that vertex, the tip frame with it."""
        P = self.positions(qpos)
        J = np.zeros((self.model.nv, self.N))
        for j in range(self.N - 1):
            r = P[j + 2:-1, :2] - P[j + 1, :2]                # vertices j + 2 .. N
            J[self.v_adr[j:], j] = -r[:, 1]
            J[self.v_adr[j:] + 1, j] = r[:, 0]
        J[self.tip_v, :] = 1.0
        return J

    def moments_of(self, qfrc):
        P = self.positions(self.data.qpos)
        fx, fy = qfrc[self.v_adr], qfrc[self.v_adr + 1]       # vertices 2 .. N
        x, y = P[2:-1, 0], P[2:-1, 1]
        # sum over the vertices beyond hinge j of (P_k - P_{j+1}) x f_k (reverse cumulative
        # sums), and the tip frame's torque
        tz = np.append(np.cumsum((x * fy - y * fx)[::-1])[::-1], 0.0)
        Fx = np.append(np.cumsum(fx[::-1])[::-1], 0.0)
        Fy = np.append(np.cumsum(fy[::-1])[::-1], 0.0)
        pj = P[1:self.N + 1]
        return tz - (pj[:, 0] * Fy - pj[:, 1] * Fx) + qfrc[self.tip_v]

    def apply_moments(self, moments, scale, stiffness_change):
        M = np.broadcast_to(np.multiply(moments, scale), (self.N,))
        if stiffness_change is not None:
            M = M - stiffness_change * self.angles()
        C = M - np.append(M[1:], 0.0)                          # couple on edge k = 1 .. N
        e, l2 = self._edges(self.positions(self.data.qpos))
        # edges 1 .. N - 1 (vertex k to k + 1): forces C / l along n = z x e / l, +f on vertex
        # k + 1 and -f on vertex k (vertex 1 is pinned); the last edge is the tip frame: a torque
        c = C[:-1] / l2[1:-1]
        fx, fy = -c * e[1:-1, 1], c * e[1:-1, 0]
        q = self.data.qfrc_applied
        q[self.v_adr] = fx - np.append(fx[1:], 0.0)
        q[self.v_adr + 1] = fy - np.append(fy[1:], 0.0)
        q[self.tip_v] = C[-1]

    # -- stiffness and damping -------------------------------------------------------------
    def set_stiffness(self, k, factor):
        # the flex's bending records, read every step (its Rayleigh damping follows them)
        self.model.flex_bending[self._k_idx] = self._k0 * factor
        return True

    def damping(self):
        # the weak axis: coefficient x sqrt(k1 k2), hinge equivalent 2 x that per vertex
        k1, dk = self.model.flex_bending[self._k_idx[::2]], self.model.flex_bending[self._k_idx[1::2]]
        return self.model.flex_damping[self.flex] * 2.0 * np.sqrt(k1 * (k1 + dk))

    def scale_damping(self, factor):
        # the flex's damping is its coefficient x its stiffness: it follows set_stiffness
        pass

    def set_damping(self, b):
        raise ParameterError("representation", "rod", "'hinge' (per-joint damping is a hinge-chain notion)")

    def save_damping(self):
        return float(self.model.flex_damping[self.flex]), self.model.dof_damping.copy()

    def scale_saved_damping(self, saved, factor):
        self.model.flex_damping[self.flex] = saved[0] * factor
        self.model.dof_damping[:] = saved[1] * factor

    def restore_damping(self, saved):
        self.model.flex_damping[self.flex] = saved[0]
        self.model.dof_damping[:] = saved[1]


register(RodBuilder())
