"""SensorReading: waits until a sensor proposition of the simulated robot turns true."""

from flexbe_core import EventState

from atlas_sim_flexbe_states.capability_request import CapabilityRequest


class SensorReading(EventState):
    """
    Returns once the named sensor of the simulated robot reads true (e.g. obj_detected).

    The simulator node answers the sensor's request when the sensor is (or becomes) true.

    -- sensor       string   Sensor proposition as in the system config.

    <= found                 The sensor reads true.
    """

    def __init__(self, sensor):
        super().__init__(outcomes=['found'])
        self._run = CapabilityRequest(sensor, type(self).__name__)

    def on_enter(self, userdata):
        self._run.start()

    def execute(self, userdata):
        return self._run.outcome('found', None)  # no reading yet (or no simulator): keep waiting
