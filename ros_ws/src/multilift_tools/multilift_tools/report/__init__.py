"""`multilift reproduce`: the seed's §2.8 and Ch. 4 rerun headless, measured, drawn and written
to docs/reproduction.md. World frame, z up, SI units; the seed's frame is z down.

    command      the command line (`reproduce_main`)
    cases        the cases, run in worker processes, and their progress
    single_lift  the single-lift table (seed §2.8.1, §4.1) the unit tests regenerate
    seed         what the seed says (values, figure captions), the scenarios of its cases
    numbers      the typed measurements (frozen dataclasses with units), the mission's phases
    measure      the measurements on the cases' results
    figures      the report's figures: the plot functions plus captions and marks
    template     the one renderer: templates/reproduction.md filled from a numbers.Report
    write        the cases' results -> figures and reproduction.md
"""
