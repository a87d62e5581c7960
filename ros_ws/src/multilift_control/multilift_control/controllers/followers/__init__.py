"""The shipped follower controllers, a module each (`multilift_control.controllers`)."""
