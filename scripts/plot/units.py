"""Units of CoReDEM's timeseries columns and case keys, for axis labels (plot_run.py,
campaign_plot.py). The column names carry their unit as a suffix (docs/orchestrator.md
"timeseries.csv"); the few that do not are listed here."""

# Suffix of a column or key name -> unit (the longest suffix wins).
SUFFIXES = {
    "_kg_per_s": "kg/s", "_m_per_s": "m/s", "_J": "J", "_kg": "kg", "_Pa": "Pa", "_m": "m", "_s": "s", "_K": "K",
    "_W": "W", "_mol": "mol",
}
# Whole names (the last component of a key path such as particles[0].diameter) -> unit.
NAMES = {
    "t": "s", "dt": "s", "dt_dem": "s", "end": "s", "dt_max": "s", "dt_min": "s",
    "mean_T_p": "K", "min_T_p": "K", "max_T_p": "K", "temperature": "K", "T_g": "K", "T": "K",
    "courant": "-", "n_sub": "-", "particles": "-", "contacts": "-", "count": "-",
    "diameter": "m", "density": "kg/m^3", "viscosity": "Pa s", "conductivity": "W/(m K)",
    "cp": "J/(kg K)", "pressure": "Pa", "k_n": "N/m", "e_n": "-", "friction": "-",
    "emissivity": "-", "velocity": "m/s", "U": "m/s", "inlet_velocity": "m/s",
    "molar_mass": "kg/mol", "removal_fraction": "-",
}


def unit_of(name):
    """The unit of a column or key path ('' when unknown)."""
    base = name.split(":")[-1]  # campaign scalars: "mean:mean_T_p"
    last = base.split(".")[-1].split("]")[-1]
    if last in NAMES:
        return NAMES[last]
    best = ""
    for suffix, unit in SUFFIXES.items():
        if base.endswith(suffix) and len(suffix) > len(best):
            best = suffix
    return SUFFIXES.get(best, "")


def label(name, unit=None):
    """'name [unit]' ([-] for dimensionless, [?] when the unit is unknown)."""
    u = unit if unit is not None else unit_of(name)
    return f"{name} [{u or '?'}]"
