"""Built-in simulators: pymunk (Chipmunk) and Box2D, driven by one stepping loop."""
