"""respec: a ROS-free library that builds LTL formulas and GR(1) specifications, and the model
types every package shares.

The LTL library:
    ltl                  the LTL formula representation and its slugs printers
    spec                 GR1Specification: sections, printers, merging with stable order
    parsing              parsers for structuredslugs, slugsin and LTLSpecification sections
    nesting              how deeply formulas may nest (one limit for every parser and process)

(The ATLAS paper's encoding, its formula families and the sub-specifications made of them, is
``ltl_specification.activation_outcomes`` and ``ltl_specification.components``: only the
compiler uses it.)

Shared model types:
    robot                robot systems: RobotSystem, the abstraction, CNU capability robots,
                         the FlexBE state classes of a workspace (see ``respec.robot``)
    automaton            the synthesized Automaton (the FSAutomaton message shape)

The suite's vocabulary (``respec.vocabulary``): the naming rules of propositions, outcomes and
lists (``naming``), the result codes and CodedError (``errors``), private directories
(``private_files``).
"""
