# # Statistical vs boundary-element normal law of one rough surface
#
# Builds, for one surface, the statistical laws of this package (strongly anisotropic elastic,
# elasto-plastic, McCool's GW) and the boundary-element law of the surface itself
# (rough_contact.bem), prints and plots p, A/A0 and k = -dp/dh against h/sigma and against the
# load, the ratios statistical/BEM and the load range over which they agree within ``--tol``.
# The work is done by rough_contact.law_comparison (its docstring describes the inputs).
#
# Run: ``bash run.sh python demos/compare_laws.py --surface anisotropic [--tol 0.1]
# [--realisations 8] [--ppw 8] [--psi 0.35] [--out results/compare]``;
# ``--moments m00 m20 m02 m40 m04`` (um convention) or ``--height-map file.npy --dx STEP``.

import sys

from rough_contact.law_comparison import main

if __name__ == "__main__":
    main(sys.argv[1:])
