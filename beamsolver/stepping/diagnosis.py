"""What went wrong, from what the solver knows: the source of a non-finite value, the state of
the tangent (indefinite, ill-conditioned) and the mesh (elements turning too far).

Used by ``solve`` to name the input behind a NaN (``nonfinite_source``) and to
add advice to a ``ConvergenceError`` (``advice``).
"""
import numpy as np

from ..nonlinear.definiteness import negative_eigenvalues
from ..failures import DampingStalled, NotConverged, SingularTangent

__all__ = ["nonfinite_source", "advice", "stiffness_spread", "pushing_point", "ILL_CONDITIONED"]

ILL_CONDITIONED = 1e10     # ratio of scaled diagonal stiffnesses called ill-conditioned


def nonfinite_source(problem, H, t):
    """``(input, message)`` naming what makes the residual of ``problem`` at poses ``H`` and time
    ``t`` non-finite (``input``: True when it is the user's input), or ``None`` if all is finite."""
    system = problem.system
    bad = np.flatnonzero(~np.all(np.isfinite(H.reshape(len(H), -1)), axis=1))
    if len(bad):
        return True, f"the poses of nodes {bad[:10].tolist()} are not finite (initial_poses or a prescribed motion)"
    model = system.model
    if len(system.load_scales):
        lf = system.load_factors(t)
        j = np.flatnonzero(~np.isfinite(lf))
        if len(j):
            k = int(j[0])
            what = f"add_load(node {model.loads[k].node})" if k < len(model.loads) else \
                f"add_line_load({model.line_loads[k - len(model.loads)].beam!r})"
            return True, f"{what}: scale({t:.6g}) = {float(lf[k])!r} is not finite"
    for node, comp, f in system.fix_values:
        v = float(f(t))
        if not np.isfinite(v):
            return True, f"fix(node {node}): values[{comp}]({t:.6g}) = {v!r} is not finite"
    for g in system.groups:                 # per element type (k nodes each)
        f = g.element_type.evaluate(H, g.nodes, g.ref, False)[0]
        e = np.flatnonzero(~np.all(np.isfinite(f), axis=1))
        if len(e):
            return False, f"the internal forces of element {int(g.elements[e[0]])} are not finite"
    for c in problem.contributions:
        rc = system.assemble_blocks(H, c.evaluate(H, False)[0])[0]
        nodes = np.flatnonzero(~np.all(np.isfinite(rc.reshape(-1, 6)), axis=1))
        if len(nodes) and c is problem.contact:
            decl = _contact_declaration(model, nodes)
            return True, (f"the contact forces of {decl} are not finite at nodes {nodes[:10].tolist()}: "
                          "do two beams share a centre line (no contact normal)?")
        if len(nodes):
            return True, f"the forces of contribution {c.name!r} are not finite at nodes {nodes[:10].tolist()}"
    return None


def _contact_declaration(model, nodes):
    beam_of = {int(n): b.id for b in model.beams for n in b.nodes}
    ids = {beam_of.get(int(n)) for n in nodes}
    for i, d in enumerate(model.contacts):
        if ids & {b.id for b in d.slave + d.master}:
            return (f"add_contact no. {i} (slave beams {[b.id for b in d.slave]}, "
                    f"master beams {[b.id for b in d.master]})")
    return "a contact declaration"


def pushing_point(problem, H):
    """Where contact pushes the poses ``H`` hardest: ``add_contact no. k: <slave element> against
    <master element> (normal force, gap; points in contact)``.  Commits ``H`` to the contact
    contribution to read its point table: for a run that stops there."""
    cs = problem.contact
    if cs is None:
        return "no contact declared"
    try:
        cs.commit(H)
        c = cs.results(H)
    except Exception:           # advice only: never hide the failure being reported
        return "the contact points could not be evaluated"
    on = np.flatnonzero(c["normal_force"] > 0)
    if not len(on):
        return "no contact point carries force"
    k = on[np.argmax(c["normal_force"][on])]
    e, m = int(c["slave_element"][k]), int(c["master_element"][k])
    decl = next((d.index for d in cs.decls if e in d.slave_el and m in d.master_el), "?")
    return (f"the largest push: add_contact no. {decl}: {cs.element_label(e)} against "
            f"{cs.element_label(m)}, normal force {c['normal_force'][k]:.3g} at gap {c['gap'][k]:.3g}; "
            f"{len(on)} points in contact")


def stiffness_spread(system, K):
    """Ratio of the largest to the smallest diagonal stiffness of the free unknowns, translations
    scaled by the model size (``K_uu L^2`` against ``K_ww``): a unit-invariant, cheap lower bound
    of the condition number of ``K``."""
    d = np.abs(K.diagonal())
    is_u = (system.free_dofs % 6) < 3
    d = np.where(is_u, d * system.length_scale**2, d)
    return float(d.max() / d.min()) if len(d) and d.min() > 0 else np.inf


def _tangent_state(problem, H, t):
    """``(negative eigenvalues, stiffness spread)`` of the tangent at ``H`` (``None`` if unknown)."""
    try:
        K = problem.tangent(problem.evaluate(H, t, tangent=True))
        spread = stiffness_spread(problem.system, K)
        return (negative_eigenvalues(K)[0] if np.isfinite(spread) else None), spread
    except Exception:           # advice only: never hide the failure being reported
        return None, None


def advice(failure, problem, H, t):
    """Advice for a ``ConvergenceError`` after ``failure`` of ``problem`` from the converged state
    ``H`` at ``t``."""
    if not isinstance(failure, (NotConverged, DampingStalled, SingularTangent)):
        return ""
    neg, cond = _tangent_state(problem, H, t)
    if isinstance(failure, SingularTangent):
        if cond is not None and cond > ILL_CONDITIONED:
            return (f"; the tangent is ill-conditioned (its diagonal stiffnesses, translations scaled by the "
                    f"model size, span a ratio of {cond:.1e}): "
                    "stiffnesses many orders of magnitude apart (sections, penalties, supports) leave "
                    "the linear solve without significant digits")
        return "; is a rigid-body mode unconstrained?"
    if neg:
        return (f"; the tangent at t = {t:.6g} is already indefinite ({neg} negative eigenvalue"
                f"{'s' if neg > 1 else ''}): the path has passed a limit point or bifurcation, which a "
                "force-controlled quasi-static solve cannot follow: prescribe displacements, add supports "
                "or an imperfection")
    return ("; the tangent is positive definite at the last converged state (no limit point there): large "
            "rotations of slender beams need small load steps where the strain-space update does not apply "
            "(joined, guided or supported beams): lower min_step_ratio or use more steps; if a contact lost "
            "its support, add supports or prescribe displacements")
