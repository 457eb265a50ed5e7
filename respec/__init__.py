"""respec: a ROS-free library that builds LTL formulas and GR(1) specifications.

Modules:
    ltl       the LTL formula representation and its slugs printers
    systems   locating and loading robot system configuration files (config/<system>.yaml)
"""
