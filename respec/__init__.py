"""respec: a ROS-free library that builds LTL formulas and GR(1) specifications.

Modules:
    ltl                  the LTL formula representation and its slugs printers
    spec                 GR1Specification: sections, printers, merging with stable order
    parsing              parsers for structuredslugs, slugsin and LTLSpecification sections
    nesting              how deeply formulas may nest (one limit for every parser and process)
    systems              locating and loading robot system configuration files (config/<system>.yaml)
    abstraction          a robot's discrete abstraction (the ``abstraction:`` section), validated
    activation_outcomes  the paper's formula families, one function per equation (3)-(20)
    components           sub-specifications (control modes, actions, initial conditions, goals),
                         made of FormulaGroups (the provenance of every formula)
"""
