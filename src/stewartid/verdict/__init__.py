"""Which of several identified models to trust on the same data, and why: the policy, the
rule, the consensus of close methods and the entries the trusted result is unsure of."""
