"""The shipped leader controllers, a module each (`multilift_control.controllers`)."""
