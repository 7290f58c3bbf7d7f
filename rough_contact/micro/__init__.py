"""The micro-model: one asperity, the summit population, tabulated normal laws, the BEM law.

Modules:
    asperity        elliptic integrals, elliptic Hertz, ZMC elasto-plastic transition, plastic
                    asperity (paper sections 3-6).
    population      sums over the summit population vs separation: elastic, elasto-plastic,
                    McCool's Greenwood-Williamson equivalent (sections 5-7).
    tables          how a normal law is tabulated: the package's one cubic Hermite interpolant
                    and the adaptive/data/population table builders (``Table``), evaluated at
                    points by ``rough_contact.interface.normal.NormalLaw``.
    bem             the normal (and full-stick tangential) law computed by FFT boundary elements.
    law_comparison  statistical vs BEM laws of one surface (command line:
                    ``demos/compare_laws.py``).

Units: mm, N, MPa. Pure layer: numpy and scipy (Tamaas optional for the BEM); imports only
``rough_contact.surface`` and ``rough_contact.validation`` below it.
"""
