"""The suite's vocabulary: the words every package and every answer share, one home for each.

    naming         the naming rules: proposition suffixes (``_a``, ``_c``, ``_m``), the state
                   machine's outcomes, FlexBE's class markers, name lists
    errors         the result codes (ErrorCode, the SynthesisErrorCodes numbers), CodedError,
                   the commands' exit statuses, how a message quotes a user's value
    private_files  the directories only this user may write to (byproducts, the strategy cache)
"""
