"""`GraphEvents`: a thread that calls back on every change of the ROS graph a node sees (rcl's
graph guard condition, waited on through ctypes on librcl), for the Foxglove bridge to look at
the graph again within milliseconds of a discovery.
"""
from __future__ import annotations

import threading
from typing import Any


class GraphEvents:
    """Calls `on_change()`, from a thread of its own, each time the rmw reports a change of the
    ROS graph as `node` sees it (a participant, publisher or subscription discovered or gone):
    rcl's graph guard condition of the node (`rcl_node_get_graph_guard_condition`). rclpy
    (Jazzy) neither exposes it nor lets its EventsExecutor wait on guard conditions, so the
    thread waits on it in an rcl wait set of its own, through ctypes on librcl (the library
    rclpy has loaded), together with a guard condition of its own that `close` triggers.
    `on_change` should be cheap: a burst of discovery events calls it once per event."""

    def __init__(self, node: Any, on_change) -> None:
        import ctypes
        from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy

        class WaitSet(ctypes.Structure):  # rcl_wait_set_t (rcl/wait.h)
            _fields_ = [(f'{kind}{part}', ctypes.c_void_p if part == 's' else ctypes.c_size_t)
                        for kind in ('subscription', 'guard_condition', 'timer', 'client',
                                     'service', 'event') for part in ('s', '_count')] + [
                ('impl', ctypes.c_void_p)]

        class Allocator(ctypes.Structure):  # rcutils_allocator_t
            _fields_ = [(name, ctypes.c_void_p) for name in (
                'allocate', 'deallocate', 'reallocate', 'zero_allocate', 'state')]

        rcl, rcutils = ctypes.CDLL('librcl.so'), ctypes.CDLL('librcutils.so')
        rcutils.rcutils_get_default_allocator.restype = Allocator
        rcl.rcl_node_get_graph_guard_condition.restype = ctypes.c_void_p
        rcl.rcl_node_get_graph_guard_condition.argtypes = [ctypes.c_void_p]
        wait_set_p = ctypes.POINTER(WaitSet)
        rcl.rcl_wait_set_init.argtypes = [wait_set_p] + [ctypes.c_size_t] * 6 + [
            ctypes.c_void_p, Allocator]
        rcl.rcl_wait_set_add_guard_condition.argtypes = [wait_set_p, ctypes.c_void_p,
                                                         ctypes.c_void_p]
        rcl.rcl_wait_set_clear.argtypes = [wait_set_p]
        rcl.rcl_wait.argtypes = [wait_set_p, ctypes.c_int64]
        rcl.rcl_wait_set_fini.argtypes = [wait_set_p]
        self._rcl, self._rcutils, self._ctypes = rcl, rcutils, ctypes
        self.on_change = on_change
        self._node = node  # keeps the rcl node (and its graph guard condition) alive
        self._graph = rcl.rcl_node_get_graph_guard_condition(node.handle.pointer)
        if not self._graph:
            raise RuntimeError('the node has no graph guard condition')
        self._stop = _rclpy.GuardCondition(node.context.handle)
        self._wait_set = WaitSet()
        ret = rcl.rcl_wait_set_init(ctypes.byref(self._wait_set), 0, 2, 0, 0, 0, 0,
                                    node.context.handle.pointer,
                                    rcutils.rcutils_get_default_allocator())
        if ret != 0:
            rcutils.rcutils_reset_error()
            self._stop.destroy_when_not_in_use()
            raise RuntimeError(f'rcl_wait_set_init returned {ret}')
        self._stopping = False
        self.error: str | None = None
        self._thread = threading.Thread(target=self._run, daemon=True, name='graph-events')
        self._thread.start()

    def _run(self) -> None:
        rcl, ctypes = self._rcl, self._ctypes
        wait_set = ctypes.byref(self._wait_set)
        while not self._stopping:
            rcl.rcl_wait_set_clear(wait_set)
            rcl.rcl_wait_set_add_guard_condition(wait_set, self._graph, None)
            rcl.rcl_wait_set_add_guard_condition(wait_set, self._stop.pointer, None)
            ret = rcl.rcl_wait(wait_set, -1)  # rcl_wait nulls the entries not triggered
            if self._stopping:
                return
            if ret != 0:
                self._rcutils.rcutils_reset_error()
                self.error = f'rcl_wait returned {ret}'
                return
            if ctypes.cast(self._wait_set.guard_conditions,
                           ctypes.POINTER(ctypes.c_void_p))[0]:
                try:
                    self.on_change()
                except Exception as error:  # noqa: BLE001 - the poll remains
                    self.error = f'{type(error).__name__}: {error}'
                    return

    def close(self) -> None:
        """Stop the thread (before the node is destroyed) and free the wait set."""
        self._stopping = True
        self._stop.trigger_guard_condition()
        self._thread.join(timeout=5)
        if not self._thread.is_alive():  # else it still waits: leave it its wait set
            self._rcl.rcl_wait_set_fini(self._ctypes.byref(self._wait_set))
            self._stop.destroy_when_not_in_use()
