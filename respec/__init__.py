"""respec: a ROS-free library that builds LTL formulas and GR(1) specifications, and the model
types every package shares.

The LTL library:
    ltl                  the LTL formula representation and its slugs printers
    spec                 GR1Specification: sections, printers, merging with stable order
    parsing              parsers for structuredslugs, slugsin and LTLSpecification sections
    nesting              how deeply formulas may nest (one limit for every parser and process)
    activation_outcomes  the paper's formula families, one function per equation (3)-(20)
    components           sub-specifications (control modes, actions, initial conditions, goals),
                         made of FormulaGroups (the provenance of every formula)

Shared model types:
    robot                robot systems: RobotSystem, the abstraction, CNU capability robots,
                         the FlexBE state classes of a workspace (see ``respec.robot``)
    automaton            the synthesized Automaton (the FSAutomaton message shape)
    naming               the naming rules of propositions (``_a``, ``_c``, ``_m``), outcomes, lists
    errors               CodedError and the error vocabulary (SynthesisErrorCodes)
"""
