"""The synthesis web GUI (ROS-free; ``synthesis_manager.programs.gui`` wires it to ROS).

    routes        the FastAPI app: page, JSON API, server-sent event streams, downloads
    backend       SynthesisBackend: the robot systems, and one object per concern behind the routes
    job_queue     JobQueue: starting, following and cancelling synthesis jobs
    jobs          what the page asks for (JobRequest), a job's record, progress and summary
    downloads     Downloads: a finished job's downloads, each built once
    repairs       RepairSearches: "Suggest fixes", a search per child process
    request_form  RequestForm: what the form offers for a system, and its live goal check
    outcome       JobOutcome: what a job ended with, typed until a route makes JSON of it
    vocabulary    the Python names the page needs (GET /api/vocabulary)
    robot_views   what each surface asks of a robot, answered per kind (modes, capabilities)
    simulations   a closed-loop run's record, and SimulationRuns: starting, following, steering them
    simulation_process  a run in its child process (atlas_sim's ATLAS, or a capability robot)
    artifacts     the downloads built from a finished job
    picture       the machine's SVG: Graphviz' dot, else Graphviz compiled to WebAssembly with Node
                  (render_dot.mjs; @viz-js/viz from npm, installed by `make setup`)
    plays         playing a finished job: the environment against its machine, or the robot
    robot_game    playing the robot as a game with an end (words, order, verdict)
    errors        request errors answered as 4xx/5xx JSON
    guards        what is refused before any route (foreign Host, large body, non-JSON POST)
    static/       index.html, style.css and the page's ES modules (app.js first)
"""
