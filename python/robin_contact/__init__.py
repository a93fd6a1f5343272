"""robin_contact: run robin-contact cases from Python and get the results as NumPy arrays
(docs/scripting.md). Pure Python: the standard library and NumPy.

    import robin_contact
    results = robin_contact.run_case("examples/two_blocks.toml",
                                     overrides={"body[2].dirichlet[1].y": -0.02})
    results.summary["converged"], results.contact["pressure"], results.history["penetration"]
    results.bodies["upper"].point_data["displacement"]
    # a case of several contact interfaces: one table per interface
    results.interfaces[0].bodies, results.interfaces[0].contact["pressure"]
    results.interface("lower", "middle").contact["pressure"]
"""

from .run import (TOOLS, Interface, Results, RunError, find_bin_directory, override_arguments,
                  read_results, run_case, toml_value)
from .vtu import VtuError, VtuFile, read_vtu

__all__ = ["TOOLS", "Interface", "Results", "RunError", "VtuError", "VtuFile",
           "find_bin_directory", "override_arguments", "read_results", "read_vtu", "run_case",
           "toml_value"]
