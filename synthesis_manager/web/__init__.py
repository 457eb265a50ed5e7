"""The synthesis web GUI (ROS-free; ``synthesis_manager.gui`` wires it to ROS).

    routes        the FastAPI app: page, JSON API, server-sent event streams, downloads
    backend       SynthesisBackend: jobs, simulations and downloads behind the routes
    jobs          what the page asks for (JobRequest), a job's record and summary
    simulations   a closed-loop run's record
    artifacts     the downloads built from a finished job
    errors        request errors answered as 4xx/5xx JSON
    static/       index.html, app.js, style.css
"""
