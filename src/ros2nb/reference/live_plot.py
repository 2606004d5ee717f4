"""A plot feeder: keeps every temperature reading and redraws a live plot with each one."""

from rclpy.node import Node
from std_msgs.msg import Float32

TOPIC = 'temperature'
QUEUE_DEPTH = 10
WINDOW_S = 60.0               # the plot shows at least this many seconds


class PlotFeeder(Node):
    """Feeds a matplotlib line with every reading on the temperature topic."""

    def __init__(self, line=None):
        super().__init__('plot_feeder')
        self.line = line          # the line to feed, or None (then redraw() only counts)
        self.times_s = []         # when each reading arrived (s, the node's clock)
        self.temps_c = []         # the readings (°C)
        self.redraws = 0
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)

    def redraw(self):
        """Give the line every point so far and ask for a redraw; never waits for it."""
        self.redraws += 1
        if self.times_s and self.temps_c:
            self.get_logger().info(f'Plotted {self.temps_c[-1]:.2f} °C at '
                                   f'{self.times_s[-1]:.3f} s, point {len(self.temps_c)}')
        if self.line is None:
            return
        start_s = self.times_s[0] if self.times_s else 0.0
        since_s = [t - start_s for t in self.times_s]   # seconds since the first reading
        self.line.set_data(since_s, self.temps_c)
        self.line.axes.set_xlim(0.0, max(WINDOW_S, since_s[-1] if since_s else 0.0))
        self.line.figure.canvas.draw_idle()

    def temperature_callback(self, msg):
        # 1. the node's time now, in seconds -> self.times_s
        # 2. the reading -> self.temps_c
        # 3. ask for a redraw
        self.times_s.append(self.get_clock().now().nanoseconds / 1e9)
        self.temps_c.append(msg.data)
        self.redraw()
