"""respec: a ROS-free library that builds LTL formulas and GR(1) specifications, and what every
package shares: the model types, the suite's vocabulary and the process runner.

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

The process runner (``respec.child_processes``): work in child processes that a cancel, a
deadline, a memory limit or a shutdown ends at once, stopped with neutral errors (syntheses,
large compilations and generations, repair searches, the GUI's simulations).
"""
