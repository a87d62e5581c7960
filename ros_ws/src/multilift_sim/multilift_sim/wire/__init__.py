"""The run's messages on the wire, without rclpy: what each carries and its bytes.

    msgvalues      the numbers our messages carry, computed once from model values
    scene          the formation drawn (markers) from those numbers
    cdr            CDR packed from them (the bytes rclpy would serialize, padding zeroed);
                   cdr_layout its rules (alignment, strings, the header), cdr_scene /tf and
                   the markers
    msgdefs        message definitions and type hashes, from the installed interface files
    tick_messages  the simulator's messages of a tick as (topic, CDR bytes)

The topics themselves are `multilift_sim.topics` (the one table).
"""
