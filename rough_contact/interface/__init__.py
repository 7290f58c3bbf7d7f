"""Pure-numpy interface laws evaluated at facet quadrature points (no dolfinx import).

Every law follows the interface-law contract of ``rough_contact.interface.contract``
(``docs/writing_a_law.md``); the equation readings are in ``docs/equations.md``.
"""
